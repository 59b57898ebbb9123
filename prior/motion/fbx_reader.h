// FBX input through the Open Asset Import Library (assimp, Debian's
// libassimp-dev): the motion of an armature and one animation of a .fbx file
// (binary or ASCII), through node_animation.h.
//
// The joints are the nodes the animation moves and the nodes between them,
// and the bones of skinned meshes. The rest pose is the nodes' transforms
// (pivots and pre-rotations baked in by assimp). The length unit comes from
// the file's UnitScaleFactor (centimetres per file unit; 1 when absent) and
// the axes from its UpAxis, FrontAxis and CoordAxis settings (a Z-up file is
// turned to Y up); key times from the animation's ticks per second.
#pragma once

#include <cstdint>
#include <string>

#include "prior/motion/motion.h"
#include "prior/motion/node_animation.h"

namespace mf {

/// The motion of the FBX document in `data`, in metres; `metres_per_unit`
/// (optional) receives the file's unit. Throws mf::InputError naming the
/// problem: not FBX or truncated (assimp's message), axis settings that are not
/// a rotation, a unit that is not positive, and those of
/// motion_from_node_animation and pick_animation.
Motion read_fbx_motion(const uint8_t* data, size_t size, const SceneReadOptions& options = {},
                       double* metres_per_unit = nullptr);

/// Reads `path` (at most kMaxSceneFileBytes; FileError when it cannot be read)
/// and read_fbx_motion on it; errors are prefixed with "<path>: ".
Motion read_fbx_file(const std::string& path, const SceneReadOptions& options = {},
                     double* metres_per_unit = nullptr);

}  // namespace mf
