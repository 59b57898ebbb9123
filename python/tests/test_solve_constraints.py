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

    def _bumped_trajectory(self, first, last, bump_m):
        """The straight line between the sample's root at the keys first - 1
        and last + 1 (the way it walks), pushed sideways by up to bump_m
        metres, facing along the line: [N, 5] rows (frame, x, z in the file's
        unit, forward_x, forward_z)."""
        m = self.motion
        r = m.root_positions[:, [0, 2]]  # metres
        a, b = first - 1, last + 1
        d = r[b] - r[a]
        side = np.array([-d[1], d[0]]) / np.linalg.norm(d)
        frames = np.arange(first, last + 1)
        t = (frames - a) / float(b - a)
        ground = (r[a] + t[:, None] * d + (bump_m * np.sin(np.pi * t))[:, None] * side) / m.length_scale
        return np.column_stack([frames, ground, np.tile(d, (len(frames), 1))])

    def test_trajectory_is_followed(self):
        model = mf.Model(MODEL)
        t = self._bumped_trajectory(16, 44, 0.3)
        keys = [0, 15, 45, 60]
        s = mf.solve(self.motion, keys, trajectory=t, method="nemf", model=model)
        ground = s.motion.root_positions[t[:, 0].astype(int)][:, [0, 2]] / self.motion.length_scale
        miss = np.linalg.norm(ground - t[:, 1:3], axis=1).max()  # file units (cm)
        self.assertLess(miss, 5.0)  # measured 1.7 cm
        self.assertLess(s.report["solutions"][0]["trajectory"]["facing_mean_deg"], 5.0)  # measured 1.1
        r = s.report["solutions"][0]["trajectory"]
        self.assertEqual(r["rows"], 29)
        self.assertAlmostEqual(r["max"], float(miss), places=2)
        # The same as frames + [N, 4] rows, and from a CSV file.
        b = mf.solve(self.motion, keys, trajectory=(t[:, 0], t[:, 1:]), method="nemf", model=model)
        np.testing.assert_array_equal(b.motion.rotations, s.motion.rotations)
        path = os.path.join(self._tmp(), "t.csv")
        with open(path, "w") as f:
            f.write("frame,x,z,forward_x,forward_z\n")
            for row in t.astype(np.float32):
                f.write("%d,%r,%r,%r,%r\n" % (int(row[0]), float(row[1]), float(row[2]), float(row[3]), float(row[4])))
        c = mf.solve(self.motion, keys, trajectory=path, method="nemf", model=model)
        np.testing.assert_array_equal(c.motion.rotations, s.motion.rotations)
        self.assertEqual(c.method, "nemf")
        # Without a method: the default for a trajectory, which follows it too.
        d = mf.solve(self.motion, keys, trajectory=t, model=model)
        self.assertEqual(d.method, "nemf-refine")
        ground = d.motion.root_positions[t[:, 0].astype(int)][:, [0, 2]] / self.motion.length_scale
        self.assertLess(np.linalg.norm(ground - t[:, 1:3], axis=1).max(), 5.0)
        self.assertEqual(mf.solve(self.motion, keys, model=model).method, "nemf-detail")

    def _tmp(self):
        import tempfile
        d = tempfile.mkdtemp(prefix="mf-traj-")
        self.addCleanup(lambda: __import__("shutil").rmtree(d, ignore_errors=True))
        return d

    def test_bad_trajectories(self):
        m = self.motion
        row = [[30, 0.0, 0.0, 0.0, 1.0]]
        with self.assertRaises(mf.InvalidArgumentError) as e:
            mf.solve(m, [0, 60], trajectory=row, method="interp")
        self.assertIn("cannot follow a trajectory; the methods that can: nemf", str(e.exception))
        for t, text in [([[30, 0, 0, 0, 0]], "zero length"), ([[30, np.nan, 0, 0, 1]], "finite"),
                        ([[30, 0, 0, 0]], "[N, 5]"), ([[-1, 0, 0, 0, 1]], "non-negative integers"),
                        ([[2.5, 0, 0, 0, 1]], "non-negative integers"), (([1, 2], [[0, 0, 0, 1]]), "[2, 4]")]:
            with self.subTest(t=t):
                with self.assertRaises(mf.InvalidArgumentError) as e:
                    mf.solve(m, [0, 60], trajectory=t, method="nemf")
                self.assertIn(text, str(e.exception))
        path = os.path.join(self._tmp(), "bad.csv")
        with open(path, "w") as f:
            f.write("frame,x,z,forward_x,forward_z\n5,0,0,0,1\n4,0,0,0,1\n")
        with self.assertRaises(mf.InvalidArgumentError) as e:
            mf.Constraints().load_trajectory(path)
        self.assertIn(path + ":3: frame 4 comes after frame 5", str(e.exception))
        with self.assertRaises(mf.FileError):
            mf.Constraints().load_trajectory(path + ".missing")

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
