"""motionfield.transition through Python: two clips cut from the sample walk,
the parts kept exactly, the chosen length, only the transition, another frame
rate, a mismatched rig and bad arguments. Run with the other package tests
(capi_python)."""

import os
import unittest

import numpy as np

import motionfield as mf

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.environ.get("MF_SOURCE_DIR", os.path.normpath(os.path.join(HERE, "..", "..")))
SAMPLE = os.path.join(SOURCE, "samples", "walk_keyframes.bvh")


def cut(m, begin, end):
    return mf.Motion.from_arrays(m.rotations[begin:end], m.root_positions[begin:end], m.fps, like=m)


class TransitionTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.walk = mf.Motion.load_bvh(SAMPLE)
        cls.a = cut(cls.walk, 0, 35)
        cls.b = cut(cls.walk, 20, 61)

    def test_keep_returns_both_parts_exactly(self):
        t = mf.transition(self.a, self.b, 15, from_frame=30, to_frame=5, place="keep", method="interp")
        self.assertIsInstance(t, mf.Transition)
        self.assertEqual((t.frames, t.first_frame, t.method), (15, 31, "interp"))
        m = t.motion
        self.assertEqual(m.frame_count, 31 + 15 + 36)
        self.assertTrue(np.all(np.isfinite(m.rotations)))
        np.testing.assert_array_equal(m.rotations[:31], self.a.rotations[:31])
        np.testing.assert_array_equal(m.root_positions[46:], self.b.root_positions[5:])
        np.testing.assert_array_equal(m.rotations[46:], self.b.rotations[5:])
        self.assertEqual(m.joint_names, self.a.joint_names)

    def test_auto_placement_keeps_heights_and_reports_the_chosen_length(self):
        t = mf.transition(self.a, self.b, method="interp")
        self.assertTrue(10 <= t.frames <= 60)
        self.assertTrue(any("the transition has %d frames" % t.frames in w for w in t.warnings), t.warnings)
        self.assertIn("the transition has", t.motion.warnings)
        m = t.motion
        np.testing.assert_array_equal(m.root_positions[:35], self.a.root_positions)
        np.testing.assert_allclose(m.root_positions[35 + t.frames:, 1], self.b.root_positions[:, 1], atol=1e-5)

    def test_only_transition(self):
        whole = mf.transition(self.a, self.b, 12, method="interp").motion
        t = mf.transition(self.a, self.b, 12, only_transition=True, method="interp")
        self.assertEqual(t.motion.frame_count, 12)
        np.testing.assert_array_equal(t.motion.rotations, whole.rotations[35:47])

    def test_clip_b_at_60_fps(self):
        b60 = mf.resample(self.b, 60.0, method="cubic")
        t = mf.transition(self.a, b60, 10, place="keep", method="interp")
        self.assertEqual(t.motion.fps, self.a.fps)
        self.assertEqual(t.motion.frame_count, 35 + 10 + 41)
        self.assertTrue(any("resampled" in w for w in t.warnings), t.warnings)

    def test_mismatched_rig_and_bad_arguments(self):
        parents = list(self.b.parents)
        parents[-1] = 0
        other = mf.Motion.from_arrays(self.b.rotations, self.b.root_positions, self.b.fps,
                                      joint_names=self.b.joint_names, parents=parents, offsets=self.b.offsets)
        with self.assertRaisesRegex(mf.InvalidArgumentError, "clip B's rig differs from A's"):
            mf.transition(self.a, other, 10, method="interp")
        with self.assertRaisesRegex(mf.InvalidArgumentError, "from_frame"):
            mf.transition(self.a, self.b, 10, from_frame=35, method="interp")
        with self.assertRaises(mf.InvalidArgumentError):
            mf.transition(self.a, self.b, 0, method="interp")
        with self.assertRaisesRegex(mf.InvalidArgumentError, "place"):
            mf.transition(self.a, self.b, 10, place="here", method="interp")
        with self.assertRaises(TypeError):
            mf.transition(self.a, "b.bvh", 10, method="interp")

    def test_constraints_are_frames_of_the_output(self):
        c = {"targets": [{"frame": 40, "joint": "Hand_R", "position": [0, 100, 0]}]}
        t = mf.transition(self.a, self.b, 10, place="keep", constraints=c, method="interp")
        self.assertEqual(t.report["solutions"][0]["targets"]["count"], 1)
        with self.assertRaises(mf.InvalidArgumentError):
            mf.transition(self.a, self.b, 10, place="keep", method="interp",
                          constraints={"targets": [{"frame": 86, "joint": "Hand_R", "position": [0, 100, 0]}]})


if __name__ == "__main__":
    unittest.main()
