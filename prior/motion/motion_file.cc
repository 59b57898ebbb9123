#include "prior/motion/motion_file.h"

#include <algorithm>
#include <cctype>
#include <cstring>

#include "prior/motion/errors.h"

namespace mf {
namespace {

bool starts_with(const uint8_t* data, size_t size, const char* magic) {
  const size_t n = std::strlen(magic);
  return size >= n && std::memcmp(data, magic, n) == 0;
}

}  // namespace

const char* to_string(MotionFormat format) {
  switch (format) {
    case MotionFormat::Bvh: return "BVH";
    case MotionFormat::Gltf: return "glTF";
    case MotionFormat::Fbx: return "FBX";
  }
  return "?";
}

MotionFormat detect_motion_format(const std::string& name, const uint8_t* head, size_t size) {
  if (starts_with(head, size, "glTF")) return MotionFormat::Gltf;
  if (starts_with(head, size, "Kaydara FBX Binary")) return MotionFormat::Fbx;
  size_t at = starts_with(head, size, "\xEF\xBB\xBF") ? 3 : 0;
  while (at < size && std::isspace(head[at])) ++at;
  if (starts_with(head + at, size - at, "; FBX")) return MotionFormat::Fbx;
  if (starts_with(head + at, size - at, "HIERARCHY")) return MotionFormat::Bvh;
  if (starts_with(head + at, size - at, "{")) return MotionFormat::Gltf;
  const size_t dot = name.rfind('.');
  std::string ext = dot == std::string::npos || name.find('/', dot) != std::string::npos ? "" : name.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == "bvh") return MotionFormat::Bvh;
  if (ext == "glb" || ext == "gltf") return MotionFormat::Gltf;
  if (ext == "fbx") return MotionFormat::Fbx;
  throw InputError("cannot tell the format of " + name +
                   ": it is not BVH (HIERARCHY), glTF (a GLB or JSON) or FBX, and its name does not end in .bvh, "
                   ".glb, .gltf or .fbx");
}

}  // namespace mf
