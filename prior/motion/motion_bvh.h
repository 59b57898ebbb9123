// Conversion between BVH documents (file units, Euler degrees) and mf::Motion
// (metres, quaternions). This is the BVH boundary of the internal representation.
//
// Container roots: when the BVH root has exactly one child joint and that child
// has position channels (as in rigs whose "joint_Root" sits at the origin and
// whose hips carry the motion), the root is a container. Its transform is
// composed into the child, which becomes the motion's root; on writing, the
// container's channels are written as identity / its offset and the child's
// channels carry the whole root motion, so every global pose is preserved.
// Position channels on other non-root joints replace the offset: their frame-0
// value becomes the motion skeleton's offset (animated bone lengths are not
// represented).
#pragma once

#include "prior/motion/bvh.h"
#include "prior/motion/motion.h"

namespace mf {

struct BvhUnits {
  /// Metres per file length unit: 0.01 for centimetres (the default, as in most
  /// mocap BVH), 1 for metres.
  double length_scale = 0.01;
};

/// Throws mf::InputError if the document has no frames or a joint's rotation
/// channels are not three distinct axes (or absent), or the motion root has no
/// position channels and no offset can stand for its translation.
Motion motion_from_bvh(const BvhDocument& doc, const BvhUnits& units = {});

/// Writes `motion` with the hierarchy, offsets, channel layout and End Sites of
/// `layout` (the input document, typically). Joints are matched by name; every
/// joint of the motion's skeleton must exist in the layout and vice versa (except
/// a container root, see above). frame_time = 1 / motion.fps. Euler angles are
/// extracted continuously from frame to frame.
BvhDocument motion_to_bvh(const Motion& motion, const BvhDocument& layout, const BvhUnits& units = {});

/// A layout for a motion with no source file: every joint with the channels
/// "Xposition Yposition Zposition Zrotation Xrotation Yrotation" on the root and
/// "Zrotation Xrotation Yrotation" elsewhere, End Sites on leaves.
BvhDocument default_bvh_layout(const Skeleton& skeleton, const BvhUnits& units = {});

/// Convenience: read a BVH file into a Motion (and its document, for writing back).
Motion read_motion(const std::string& path, BvhDocument* layout_out = nullptr, const BvhUnits& units = {});
void write_motion(const std::string& path, const Motion& motion, const BvhDocument& layout,
                  const BvhUnits& units = {});

}  // namespace mf
