"""In-betweening and resampling from Python with motionfield.

    PYTHONPATH=python /usr/bin/python3 python/examples/inbetween_resample.py \\
        samples/walk_keyframes.bvh out/

Keeps every 10th frame of the clip as a keyframe, fills the rest, then
resamples the result to 60 fps; writes out/inbetween.bvh and out/inbetween-60fps.bvh.
Uses the default model and the default method, as the CLI does without
options (the model's best method; plain interpolation when there is no model).
"""

import os
import sys
import time

import numpy as np

import motionfield as mf


def main(argv):
    if len(argv) != 3:
        print(__doc__)
        return 2
    in_path, out_dir = argv[1], argv[2]
    os.makedirs(out_dir, exist_ok=True)
    mf.set_num_threads(1)
    print("motionfield %s (%s), 1 thread, model: %s" % (mf.__version__, mf.library_path(),
                                                        mf.default_model_path() or "none"))

    clip = mf.Motion.load_bvh(in_path)
    print("input: %s, %d frames at %g fps, %d joints" % (in_path, clip.frame_count, clip.fps, clip.joint_count))
    keys = list(range(0, clip.frame_count, 10))
    if keys[-1] != clip.frame_count - 1:
        keys.append(clip.frame_count - 1)

    t0 = time.perf_counter()
    filled = mf.inbetween(clip, keys)
    t1 = time.perf_counter()
    err = np.abs(filled.global_positions - clip.global_positions).max()
    print("inbetween (%s): %d keyframes, %.1f ms, largest joint position change %.3f m"
          % (mf.default_method(), len(keys), 1e3 * (t1 - t0), err))
    filled.save_bvh(os.path.join(out_dir, "inbetween.bvh"))

    up = mf.resample(filled, 60.0)
    t2 = time.perf_counter()
    print("resample to 60 fps: %d -> %d frames, %.1f ms" % (filled.frame_count, up.frame_count, 1e3 * (t2 - t1)))
    up.save_bvh(os.path.join(out_dir, "inbetween-60fps.bvh"))
    print("wrote %s" % ", ".join(os.path.join(out_dir, f) for f in ("inbetween.bvh", "inbetween-60fps.bvh")))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
