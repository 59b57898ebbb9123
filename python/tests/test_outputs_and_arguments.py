"""The Python package refuses what the CLI refuses, with TypeError for wrong
types and ValueError (InvalidArgumentError) for wrong values, before anything
crosses into C; and its outputs go through the C API's one writer
(docs/RELIABILITY.md, "Outputs and clients").

    MOTIONFIELD_LIBRARY=build/capi/libmotionfield.so PYTHONPATH=python \\
        /usr/bin/python3 -m unittest python/tests/test_outputs_and_arguments.py -v
"""

import math
import os
import stat
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import motionfield as mf

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.environ.get("MF_SOURCE_DIR", os.path.normpath(os.path.join(HERE, "..", "..")))
SAMPLE = os.path.join(SOURCE, "samples", "walk_keyframes.bvh")


class IntegersTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.walk = mf.Motion.load_bvh(SAMPLE)

    def test_integers_never_wrap_around(self):
        with self.assertRaisesRegex(ValueError, r"keyframes item 1 must be between -2147483648 and 2147483647, "
                                                r"not 4294967326"):
            mf.inbetween(self.walk, [0, 2**32 + 30, 60], method="interp")
        with self.assertRaisesRegex(ValueError, "gap_end must be between .* not 4294967326"):
            mf.fill(self.walk, 1, 2**32 + 30, method="interp")
        with self.assertRaisesRegex(ValueError, "alternatives must be between 0 and 16, not 4294967296"):
            mf.solve(self.walk, [0, 60], alternatives=2**32, method="interp")
        with self.assertRaisesRegex(ValueError, "max_iterations must be between 0 and 100000, not -1"):
            mf.inbetween(self.walk, [0, 60], method="interp", max_iterations=-1)
        with self.assertRaisesRegex(ValueError, "seed must be between 0 and"):
            mf.inbetween(self.walk, [0, 60], method="interp", seed=-1)
        with self.assertRaisesRegex(ValueError, "frame must be between"):
            mf.Constraints().add_target(2**40, "Hips", [0, 0, 0])
        with self.assertRaisesRegex(ValueError, "frames item 0 must be between"):
            mf.Constraints().add_keys(np.array([2**33], dtype=np.int64))

    def test_frames_must_be_integral_and_finite(self):
        with self.assertRaisesRegex(ValueError, "keyframes item 1 must be an integer, not 30.5"):
            mf.inbetween(self.walk, [0, 30.5, 60], method="interp")
        with self.assertRaisesRegex(ValueError, "keyframes item 1 must be an integer, not nan"):
            mf.inbetween(self.walk, [0, math.nan, 60], method="interp")
        with self.assertRaisesRegex(ValueError, "keyframes item 2 must be an integer, not inf"):
            mf.inbetween(self.walk, np.array([0.0, 30.0, math.inf]), method="interp")
        with self.assertRaisesRegex(ValueError, "gap_begin must be an integer, not -inf"):
            mf.fill(self.walk, -math.inf, 20, method="interp")
        with self.assertRaisesRegex(ValueError, "first must be an integer, not 1.5"):
            mf.Constraints().add_contact("Foot_L", 1.5, 10)
        # An integral float is the integer, as in the CLI's batch lines (30.0 is frame 30).
        a = mf.inbetween(self.walk, [0, 30.0, 60], method="interp")
        b = mf.inbetween(self.walk, np.array([0, 30, 60], dtype=np.int64), method="interp")
        np.testing.assert_array_equal(a.rotations, b.rotations)

    def test_wrong_types_are_type_errors(self):
        with self.assertRaisesRegex(TypeError, "motion must be a Motion, not NoneType"):
            mf.inbetween(None, [0, 60])
        with self.assertRaisesRegex(TypeError, "method must be a str or None, not int|method must be a str, not int"):
            mf.inbetween(self.walk, [0, 60], method=5)
        with self.assertRaisesRegex(TypeError, "keyframes must be a sequence of integers, not str"):
            mf.inbetween(self.walk, "0,60", method="interp")
        with self.assertRaisesRegex(TypeError, "keyframes item 1 must be an integer, not str"):
            mf.inbetween(self.walk, [0, "60"], method="interp")
        with self.assertRaisesRegex(TypeError, "keyframes item 1 must be an integer, not bool"):
            mf.inbetween(self.walk, [0, True], method="interp")
        with self.assertRaisesRegex(TypeError, "fps must be a number, not str"):
            mf.resample(self.walk, "60", method="cubic")
        with self.assertRaisesRegex(TypeError, "model must be a Model or None, not str"):
            mf.inbetween(self.walk, [0, 60], model="model.mfm")
        with self.assertRaisesRegex(TypeError, "rig_map must be a dict"):
            mf.inbetween(self.walk, [0, 60], method="interp", rig_map=5)
        with self.assertRaisesRegex(TypeError, "progress must be callable"):
            mf.inbetween(self.walk, [0, 60], method="interp", progress=1)
        with self.assertRaisesRegex(TypeError, "reference must be a Motion"):
            mf.renav(None, np.zeros((10, 2)))
        with self.assertRaisesRegex(TypeError, "constraints must be a Constraints, a dict or a file's path"):
            mf.solve(self.walk, [0, 60], constraints=5, method="interp")
        # The messages name the problem; none is one the caller never gave (-2147483648).
        try:
            mf.inbetween(self.walk, [0, math.nan, 60], method="interp")
        except ValueError as e:
            self.assertNotIn("-2147483648", str(e))

    def test_the_method_is_checked_before_the_rig(self):
        small = mf.Motion.from_arrays(np.tile(np.array([1.0, 0, 0, 0], dtype=np.float32), (20, 2, 1)),
                                      np.zeros((20, 3), dtype=np.float32), 30.0, joint_names=["Hips", "Head"],
                                      parents=[-1, 0], offsets=[[0, 0, 0], [0, 10, 0]])
        with self.assertRaisesRegex(ValueError, "method 'prior' does not do in-betweening"):
            mf.inbetween(small, [0, 19], method="prior")


class OutputSetTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="mf-outputs-")
        self.walk = mf.Motion.load_bvh(SAMPLE)

    def tearDown(self):
        subprocess.run(["rm", "-rf", self.dir], check=False)

    def path(self, name):
        return os.path.join(self.dir, name)

    def test_a_report_naming_the_output_is_refused(self):
        s = mf.OutputSet()
        s.add_input(SAMPLE)
        s.add_output(self.path("o.bvh"))
        with self.assertRaisesRegex(mf.InvalidArgumentError, "the report .*o.bvh is also the output .*o.bvh"):
            s.add_output(os.path.join(self.dir, ".", "o.bvh"), "report")
        with self.assertRaisesRegex(ValueError, "is the input"):
            s.add_output(SAMPLE, "report")
        with self.assertRaisesRegex(mf.FileError, "does not exist"):
            s.add_output(self.path("nodir/r.json"), "report")

    def test_outputs_are_written_together_or_not_at_all(self):
        s = mf.OutputSet()
        s.add_output(self.path("o.glb"))
        s.add_output(self.path("r.json"), "report")
        s.write_motion(self.path("o.glb"), self.walk)
        s.write(self.path("r.json"), "{}\n")
        self.assertFalse(os.path.exists(self.path("o.glb")), "staged outputs are not in place before the commit")
        s.commit()
        with open(self.path("o.glb"), "rb") as f:
            self.assertEqual(f.read(4), b"glTF")
        with open(self.path("r.json")) as f:
            self.assertEqual(f.read(), "{}\n")
        if os.path.exists("/dev/full"):
            s = mf.OutputSet()
            s.add_output(self.path("late.bvh"))
            s.add_output("/dev/full", "report")
            s.write_motion(self.path("late.bvh"), self.walk)
            s.write("/dev/full", "{}")
            with self.assertRaisesRegex(mf.FileError, "cannot write /dev/full: No space left on device"):
                s.commit()
            self.assertEqual(sorted(os.listdir(self.dir)), ["o.glb", "r.json"])
            self.assertTrue(stat.S_ISCHR(os.stat("/dev/full").st_mode))

    def test_saves_go_through_the_writer(self):
        with open(self.path("o.bvh.tmp"), "w") as f:
            f.write("mine")
        self.walk.save_bvh(self.path("o.bvh"))
        self.walk.save_gltf(self.path("o.glb"))
        self.walk.save_bvh("/dev/null")
        self.assertTrue(stat.S_ISCHR(os.stat("/dev/null").st_mode))
        with open(self.path("o.bvh.tmp")) as f:
            self.assertEqual(f.read(), "mine")
        self.assertEqual(sorted(os.listdir(self.dir)), ["o.bvh", "o.bvh.tmp", "o.glb"])
        if os.path.exists("/dev/full"):
            with self.assertRaisesRegex(mf.FileError, "cannot write /dev/full: No space left on device"):
                self.walk.save_bvh("/dev/full")
            with self.assertRaisesRegex(mf.FileError, "cannot write /dev/full: No space left on device"):
                self.walk.save_gltf("/dev/full", format="glb")

    def test_rig_map_files_have_the_cli_limit(self):
        with open(self.path("big.json"), "w") as f:
            f.write("{" + " " * (2 << 20) + "}")
        with self.assertRaisesRegex(mf.FileError, "larger than the limit of 1 MiB for a rig map file"):
            mf.describe_rig(self.walk, model=mf.Model(os.path.join(SOURCE, "models", "motionfield-prior.mfm")),
                            rig_map=self.path("big.json"))

    def test_constraints_with_a_duplicate_key_are_refused(self):
        with self.assertRaisesRegex(ValueError, 'duplicate key "keys" in the top-level object'):
            mf.Constraints('{"keys": [], "keys": []}')


if __name__ == "__main__":
    unittest.main(verbosity=2 if "-v" in sys.argv else 1)
