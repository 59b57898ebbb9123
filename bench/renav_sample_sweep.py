"""Re-navigation of the bundled sample along straight 40-frame paths at several speeds.

The sample (samples/walk_keyframes.bvh) is re-navigated with the default model along
straight paths along +x at 30 fps, one per speed; prints the mean and end distance (m)
of the output's root from its path point (docs/BENCHMARKS.md, "Re-navigation").

    PYTHONPATH=python python3 bench/renav_sample_sweep.py [SPEED ...]
"""
import sys

import numpy as np

import motionfield as mf


def main() -> None:
    speeds = [float(v) for v in sys.argv[1:]] or [0.6, 0.9, 1.2, 1.5]
    mf.set_num_threads(1)
    ref = mf.Motion.load_bvh("samples/walk_keyframes.bvh")
    r = ref.root_positions
    speed = np.mean(np.hypot(np.diff(r[:, 0]), np.diff(r[:, 2]))) * ref.fps
    print(f"sample: {ref.frame_count} frames at {ref.fps:.1f} fps, mean ground speed {speed:.2f} m/s")
    print("| path speed | mean / end error (m) |\n|---:|---:|")
    for v in speeds:
        path = np.array([[v * i / 30.0, 0.0] for i in range(40)], dtype=np.float32)
        p = mf.renav(ref, path).root_positions
        d = np.hypot(p[:, 0] - path[:, 0], p[:, 2] - path[:, 1])
        print(f"| {v:.1f} m/s | {d.mean():.2f} / {d[-1]:.2f} |")


if __name__ == "__main__":
    main()
