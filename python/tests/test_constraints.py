"""Constraints through Python (motionfield.solve, Constraints): partial keys,
targets as numpy arrays, contact pins, alternatives, the report, and bad
constraints with their errors. Run with the other package tests (capi_python)."""

import os
import unittest

import numpy as np

import motionfield as mf

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.environ.get("MF_SOURCE_DIR", os.path.normpath(os.path.join(HERE, "..", "..")))
SAMPLE = os.path.join(SOURCE, "samples", "walk_keyframes.bvh")
MODEL = os.path.join(SOURCE, "models", "motionfield-prior.mfm")


class ConstraintsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.motion = mf.Motion.load_bvh(SAMPLE)
        cls.names = cls.motion.joint_names

    def test_partial_key_and_target_with_interpolation(self):
        m = self.motion
        hand = self.names.index("Hand_R")
        arm = self.names.index("UpperArm_L")
        goal = m.global_positions[30, hand] / m.length_scale + np.array([0, 8, 0])
        s = mf.solve(m, [0, 60], partial_keys=[(30, ["UpperArm_L"])], targets={"Hand_R": ([30], [goal])},
                     method="interp")
        self.assertEqual(len(s.motions), 1)
        np.testing.assert_array_equal(s.motion.rotations[30, arm], m.rotations[30, arm])
        reached = s.motion.global_positions[30, hand] / m.length_scale
        self.assertLess(np.linalg.norm(reached - goal), 0.5)  # file units (cm)
        r = s.report["solutions"][0]
        self.assertEqual(r["targets"]["count"], 1)
        self.assertAlmostEqual(r["targets"]["max"], float(np.linalg.norm(reached - goal)), places=3)

    def test_constraints_object_file_and_dict_agree(self):
        c = mf.Constraints().add_keys([0, 60]).add_partial_key(20, [], "position").add_contact("Foot_L", 5, 9)
        d = c.to_dict()
        self.assertEqual(d["contacts"], [{"joint": "Foot_L", "first": 5, "last": 9}])
        a = mf.solve(self.motion, constraints=c, method="interp")
        b = mf.solve(self.motion, constraints=d, method="interp")
        np.testing.assert_array_equal(a.motion.rotations, b.motion.rotations)
        np.testing.assert_array_equal(a.motion.root_positions[20], self.motion.root_positions[20])

    def test_alternatives_differ_keep_keys_and_repeat(self):
        model = mf.Model(MODEL)
        s = mf.solve(self.motion, [0, 60], alternatives=1, method="nemf", model=model, seed=3)
        self.assertEqual(len(s.motions), 2)
        for x in s.motions:
            np.testing.assert_array_equal(x.rotations[[0, 60]], self.motion.rotations[[0, 60]])
        gap = np.linalg.norm(s.motions[0].global_positions - s.motions[1].global_positions, axis=-1).mean()
        self.assertGreater(gap * 100, 0.5)  # cm
        again = mf.solve(self.motion, [0, 60], alternatives=1, method="nemf", model=model, seed=3)
        np.testing.assert_array_equal(again.motions[1].rotations, s.motions[1].rotations)

    def test_bad_constraints(self):
        m = self.motion
        cases = [
            (dict(partial_keys=[(30, ["Tail"])]), "unknown joint 'Tail'"),
            (dict(contacts=[("Foot_L", 50, 70)]), "out of range"),
            (dict(contacts=[("Foot_L", 5, 20), ("Foot_L", 10, 30)]), "overlaps"),
            (dict(targets=[(30, "Hand_R", [np.nan, 0, 0])]), "not finite"),
            (dict(targets=[(30, "Hand_R", [0, 0])]), "3 values"),
            (dict(targets={"Hand_R": ([1, 2], [[0, 0, 0]])}), "2 frames but 1 positions"),
            (dict(partial_keys=[(30, [], "up")]), "root must be"),
            (dict(alternatives=1), "single solution"),
        ]
        for kwargs, text in cases:
            with self.subTest(kwargs=kwargs):
                with self.assertRaises(mf.InvalidArgumentError) as e:
                    mf.solve(m, [0, 60], method="interp", **kwargs)
                self.assertIn(text, str(e.exception))
        with self.assertRaises(mf.InvalidArgumentError):
            mf.solve(m, method="interp")  # no keys at all
        with self.assertRaises(mf.InvalidArgumentError):
            mf.Constraints('{"keys": [{"frame": 0, "bogus": 1}]}')


if __name__ == "__main__":
    unittest.main()
