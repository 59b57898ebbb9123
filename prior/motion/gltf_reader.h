// glTF 2.0 input (tinygltf): the motion of a skinned or skin-less armature and
// one animation of a .glb or .gltf file, through node_animation.h.
//
// The joints are those of the first skin with an animated joint, or without
// one, the animated nodes (translation, rotation or scale channels) and the
// nodes between them. The rest pose is the nodes' own transforms (matrix or
// TRS). Units and axes are glTF's: metres, Y up. Key times and values may be
// floats or normalised integers; sparse accessors are refused. Images are not
// decoded; external buffers are read next to a file (not from memory).
#pragma once

#include <cstdint>
#include <string>

#include "prior/motion/motion.h"
#include "prior/motion/node_animation.h"

namespace mf {

/// The motion of the glTF document in `data` (GLB when it starts with "glTF",
/// else JSON). `base_dir`: where external buffers are ("" = none may be read).
/// Throws mf::InputError naming the problem: not glTF (tinygltf's message), an
/// accessor beyond its buffer (truncated), a node with two parents or in a
/// cycle, and those of motion_from_node_animation and pick_animation.
Motion read_gltf_motion(const uint8_t* data, size_t size, const std::string& base_dir,
                        const SceneReadOptions& options = {});

/// Reads `path` (at most kMaxSceneFileBytes; FileError when it cannot be read)
/// and read_gltf_motion on it; errors are prefixed with "<path>: ".
Motion read_gltf_file(const std::string& path, const SceneReadOptions& options = {});

}  // namespace mf
