// The motion file formats motionfield reads and how a file's format is told:
// by its content first (magic bytes), then by its name's extension.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace mf {

enum class MotionFormat { Bvh, Gltf, Fbx };

/// "BVH", "glTF", "FBX".
const char* to_string(MotionFormat format);

/// The format of a file named `name` whose first bytes are `head` (`size`
/// bytes; the first 64 are enough). Content: "glTF" (a GLB), "Kaydara FBX
/// Binary" (binary FBX), "; FBX" (ASCII FBX), "HIERARCHY" (BVH) or "{" (glTF
/// JSON), after an optional UTF-8 byte order mark and white space; otherwise
/// the extension (.bvh, .glb, .gltf, .fbx, any case). Throws mf::InputError
/// "cannot tell the format of <name>: ..." when neither says.
MotionFormat detect_motion_format(const std::string& name, const uint8_t* head, size_t size);

}  // namespace mf
