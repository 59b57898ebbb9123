"""Checks that a motion file read with motionfield.Motion.load is the motion
of a BVH: the same joints (by name, after stripping PREFIX), global joint
positions within TOL_LENGTH of the BVH's length unit and local rotations within
TOL_DEGREES, frame by frame.

    python3 compare_motion.py REF.bvh FILE [PREFIX] [--frames N]

Exit 0 when they agree; prints the largest differences either way.
"""
import sys

import numpy as np

import motionfield as mf

TOL_LENGTH = 1e-4   # in the BVH's length unit
TOL_DEGREES = 1e-3


def main() -> int:
    ref_path, path = sys.argv[1], sys.argv[2]
    prefix = sys.argv[3] if len(sys.argv) > 3 else ""
    ref = mf.Motion.load_bvh(ref_path)  # the unit detected (centimetres for the sample)
    got = mf.Motion.load(path)
    names = [n[len(prefix):] if n.startswith(prefix) else n for n in got.joint_names]
    if sorted(names) != sorted(ref.joint_names):
        print("joints differ: %s vs %s" % (names, ref.joint_names))
        return 1
    if got.frame_count != ref.frame_count or abs(got.fps - ref.fps) > 1e-9:
        print("frames differ: %d at %g fps vs %d at %g fps" % (got.frame_count, got.fps, ref.frame_count, ref.fps))
        return 1
    order = [names.index(n) for n in ref.joint_names]
    unit = ref.length_scale  # metres per BVH unit
    dp = np.abs(got.global_positions[:, order, :].astype(np.float64) - ref.global_positions) / unit
    qa = got.rotations[:, order, :].astype(np.float64)
    qb = ref.rotations.astype(np.float64)
    qa /= np.linalg.norm(qa, axis=-1, keepdims=True)
    qb /= np.linalg.norm(qb, axis=-1, keepdims=True)
    sign = np.where(np.sum(qa * qb, axis=-1, keepdims=True) < 0, -1.0, 1.0)
    # The angle between the rotations from the chord (stable near zero, unlike arccos).
    chord = np.linalg.norm(qa - sign * qb, axis=-1)
    angle = np.degrees(4 * np.arcsin(np.clip(chord / 2, 0, 1)))
    print("%s: %d joints, %d frames; largest position difference %.3g units, rotation %.3g degrees"
          % (path, len(names), got.frame_count, dp.max(), angle.max()))
    return 0 if dp.max() <= TOL_LENGTH and angle.max() <= TOL_DEGREES else 1


if __name__ == "__main__":
    sys.exit(main())
