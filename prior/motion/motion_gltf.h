// glTF 2.0 output of an mf::Motion (tinygltf): the glTF boundary of the internal
// representation, beside the BVH one (motion_bvh.h).
//
// The document is a skin-less armature and one animation:
// - one node per joint, named after it, in the skeleton's joint order (node j
//   is joint j); children = the joint's children; the scene's one root node is
//   joint 0. A node's translation is the joint's rest offset (the skeleton's
//   offsets; joint 0: its rest position), its rotation identity.
// - one animation ("motion"): per joint a rotation channel (unit quaternions,
//   glTF's (x, y, z, w) order) and for joint 0 a translation channel (the root
//   positions), LINEAR, sampled at the motion's frame times f / fps seconds.
//   Other joints' translations are constant and stay in their nodes.
// Units and axes are the motion's: metres, seconds, Y up, right-handed, which are
// glTF's. Numbers are 32-bit floats, quaternions normalised.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "prior/motion/motion.h"

namespace mf {

enum class GltfFormat {
  Binary,    ///< .glb: the JSON chunk and the buffer in a BIN chunk
  Embedded,  ///< .gltf: JSON text with the buffer as a base64 data URI
};

/// The format a file name's extension asks for: ".glb" (any case) Binary,
/// ".gltf" Embedded; false for any other name.
bool gltf_format_from_path(const std::string& path, GltfFormat* format);

/// The glTF document of `motion` (the bytes of a .glb, or the text of a .gltf).
/// Throws mf::InputError if the motion is invalid (Motion::validate: non-finite
/// numbers, zero quaternions, ...), has no frames, has a number a 32-bit float
/// cannot hold, or is too large for a glTF buffer (2 GiB).
std::vector<uint8_t> format_gltf(const Motion& motion, GltfFormat format);

/// format_gltf, written to `path` with write_file_atomically
/// (prior/util/file_writer.h); throws FileError "cannot write <path>: <reason>"
/// on I/O failure.
void write_gltf_file(const std::string& path, const Motion& motion, GltfFormat format);

}  // namespace mf
