// All of a run's outputs, written all or nothing. A subcommand names every
// output (and every input) before any work:
//
//   drift::OutputSet outputs({out, cover, mesh}, {ground, objects});  // empty paths: not given
//   ... compute; write_geotiff(depth, out); write_ply(m, mesh); ...
//   outputs.commit();
//
// The constructor refuses a path that cannot be an output (check_output_path:
// devices, FIFOs, directories, links, the run's inputs, unwritable or missing
// directories) or that is named twice, and creates every temporary file at once,
// so an unwritable directory is found before the work, not after. Writers keep
// their signatures: while the set is open, AtomicFile writes a target of the set
// into the set's temporary file. commit() renames them all into place; if it is
// not reached (an error, an exception), no output is touched and every temporary
// file is removed. SIGINT, SIGTERM and SIGHUP remove them too (temp_registry.h).
#pragma once

#include <filesystem>
#include <vector>

namespace drift {

class OutputSet {
 public:
  OutputSet(const std::vector<std::filesystem::path>& outputs,
            std::vector<std::filesystem::path> inputs = {});
  ~OutputSet();  // removes every temporary file unless commit() succeeded
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  // Every output must have been written (AtomicFile::commit on it). Replaces the
  // targets together: should a rename fail, those already replaced get their
  // old contents back. A signal meanwhile waits until all are in place.
  void commit();

  struct Staged {
    std::filesystem::path target, temp;
    int slot = -1;
    bool written = false;
  };

  // The open set's temporary file for `target`, or nullptr if none is open or
  // `target` is not one of its outputs. Used by AtomicFile.
  static Staged* staged(const std::filesystem::path& target);
  // The open set's inputs (empty if none is open), refused as outputs anywhere.
  static std::vector<std::filesystem::path> open_inputs();

 private:
  void stage(const std::filesystem::path& target);
  void remove_temps();

  std::vector<Staged> outputs_;
  std::vector<std::filesystem::path> inputs_;
  bool committed_ = false;
};

}  // namespace drift
