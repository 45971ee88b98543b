// OpenEXR 3.1's C++ library allocates header values at the size the file
// declares and parses some by their content instead (a channel list, an int),
// so a walk of the declared sizes (drift's first check) could not see what it
// would allocate: 1.8 GB from a 192-byte file. OpenEXRCore, the C library
// written for fuzzing, parses every value within its declared size and checks
// sizes against the file's; read_image has OpenImageIO read EXRs with it
// (and gives it the file's size, which OpenImageIO 2.4 does not). This runs
// that parse first, strict (an invalid attribute is an error, not skipped),
// with an allocator that refuses what a header of this size cannot need:
// should a path of OpenEXRCore 3.1.5 not check a size, it is caught here, and
// the parse being deterministic, OpenImageIO's parse of the same bytes then
// allocates no more.
#include "render/exr_header.h"

#include <OpenEXR/openexr.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::render {

namespace {

// OpenEXRCore's allocator takes no user data: the bound for the parse under
// way on this thread.
thread_local std::uint64_t t_allocation_limit = 0;
thread_local std::uint64_t t_largest_refused = 0;
thread_local std::string t_first_error;

void* bounded_allocate(std::size_t bytes) {
  if (bytes > t_allocation_limit) {
    t_largest_refused = std::max<std::uint64_t>(t_largest_refused, bytes);
    return nullptr;
  }
  return std::malloc(bytes);
}

void release(void* pointer) { std::free(pointer); }

void keep_first_error(exr_const_context_t, exr_result_t, const char* message) {
  if (t_first_error.empty() && message) t_first_error = message;
}

}  // namespace

bool has_exr_magic(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char magic[4] = {};
  return in.read(reinterpret_cast<char*>(magic), 4) && magic[0] == 0x76 && magic[1] == 0x2f &&
         magic[2] == 0x31 && magic[3] == 0x01;
}

void validate_exr_header(const std::filesystem::path& path) {
  const std::uint64_t file_size = std::filesystem::file_size(path);
  // What a header legitimately allocates is its values (at most the file)
  // and tables that grow by doubling (a pointer per attribute of >= 7 bytes),
  // plus OpenEXRCore's fixed buffers (a 4 KiB scratch, the context).
  t_allocation_limit = 2 * file_size + (std::uint64_t{1} << 20);
  t_largest_refused = 0;
  t_first_error.clear();
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = keep_first_error;
  init.alloc_fn = bounded_allocate;
  init.free_fn = release;
  init.flags = EXR_CONTEXT_FLAG_STRICT_HEADER;  // an invalid attribute is an error, not skipped
  exr_context_t context = nullptr;
  const exr_result_t result = exr_start_read(&context, path.c_str(), &init);
  if (context) exr_finish(&context);
  if (t_largest_refused > 0) {
    throw Error("cannot read image " + path.string() + ": its header asks for " +
                human_bytes(t_largest_refused) + " but the file holds " +
                std::to_string(file_size) + " bytes (the file is corrupt)");
  }
  if (result != EXR_ERR_SUCCESS) {
    throw Error("cannot read image " + path.string() + ": " +
                (t_first_error.empty() ? std::string(exr_get_default_error_message(result))
                                       : t_first_error) +
                " (the EXR header is corrupt or truncated)");
  }
}

}  // namespace drift::render
