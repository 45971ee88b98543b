#include "terrain/atomic_file.h"

#include <system_error>

#include "terrain/error.h"
#include "terrain/output_path.h"
#include "terrain/output_set.h"
#include "terrain/temp_registry.h"

namespace drift {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  stop_here_for_tests();
  if (OutputSet::Staged* s = OutputSet::staged(target_)) {
    temp_ = s->temp;
    staged_ = true;
    return;
  }
  check_output_path(target_, OutputSet::open_inputs());
  DeferSignals defer;  // a signal between creating and recording would leave the file
  temp_ = create_temp_beside(target_);
  try {
    slot_ = register_temp(temp_);
  } catch (...) {
    std::error_code ec;
    fs::remove(temp_, ec);
    throw;
  }
}

AtomicFile::~AtomicFile() {
  if (staged_) return;  // the set removes its own temporary files
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
  forget_temp(slot_);
}

void AtomicFile::commit() {
  std::error_code ec;
  if (!fs::exists(temp_, ec)) {
    throw Error("internal: nothing was written for '" + target_.string() + "'");
  }
  if (staged_) {
    if (OutputSet::Staged* s = OutputSet::staged(target_)) s->written = true;
    committed_ = true;
    return;
  }
  match_permissions(temp_, target_);
  DeferSignals defer(true);
  fs::rename(temp_, target_, ec);
  if (ec) {
    throw Error("cannot move finished output onto '" + target_.string() + "': " + ec.message());
  }
  committed_ = true;
  forget_temp(slot_);
  slot_ = -1;
}

}  // namespace drift
