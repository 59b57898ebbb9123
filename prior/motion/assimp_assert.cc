// assimp's assertion handler, replaced (see below); part of the FBX reader
// (fbx_reader.cc).
#include <stdexcept>
#include <string>

// Debian builds assimp 5.2 with its assertions on (ASSIMP_BUILD_DEBUG), and a
// failed one aborts the process: some malformed FBX files do that (fuzz_fbx:
// an animation curve without keys, FBXConverter.cpp:3456). Its calls go
// through the PLT, so this definition replaces assimp's wherever it is
// exported: by libmotionfield.so (compiled into it directly, as the static
// libraries' symbols are hidden; capi/motionfield.map) and by programs that
// link mf_prior. The failure becomes an exception, which assimp's importer
// catches and reports as the file's error ("not a valid FBX file: ...").
namespace Assimp {
__attribute__((visibility("default"), noreturn)) void aiAssertViolation(const char* expression, const char* file,
                                                                           int line) {
  throw std::runtime_error(std::string("assimp's check '") + (expression ? expression : "?") + "' failed (" +
                           (file ? file : "?") + ":" + std::to_string(line) + ")");
}
}  // namespace Assimp
