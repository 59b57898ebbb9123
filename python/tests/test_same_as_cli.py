"""Python without arguments does what the CLI does without options: the same
default model, the same default method, the same result.

The CLI is $MF_CLI (CTest sets it), else the source tree's build/cli/motionfield.
Named after test_motionfield.py on purpose: unittest discovers files in order,
and test_motionfield.py checks that importing motionfield brings no libtorch.
"""

import os
import re
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

import motionfield as mf

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.environ.get("MF_SOURCE_DIR", os.path.normpath(os.path.join(HERE, "..", "..")))
SAMPLE = os.path.join(SOURCE, "samples", "walk_keyframes.bvh")
CLI_THREADS = 1  # the CLI's default --threads


def motion_numbers(text):
    """The numbers of a BVH file's MOTION section (Frame Time included), as float64."""
    body = text.split("MOTION", 1)[1]
    return np.array([float(x) for x in re.findall(r"-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?", body)])


class SameAsCliTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.cli = os.environ.get("MF_CLI") or os.path.join(SOURCE, "build", "cli", "motionfield")
        if not os.access(cls.cli, os.X_OK):
            raise AssertionError("no CLI at %s (set MF_CLI; CTest does)" % cls.cli)
        if mf.default_model_path() is None:
            raise AssertionError("no default model (models/motionfield-prior.mfm is in the repository)")
        cls.tmp = tempfile.mkdtemp(prefix="mf-same-as-cli-")
        # A small BVH made here: the sample's first 31 frames, moved on the ground.
        walk = mf.Motion.load_bvh(SAMPLE)
        root = walk.root_positions[:31] + np.array([0.5, 0.0, -0.25], np.float32)
        small = mf.Motion.from_arrays(walk.rotations[:31], root, walk.fps, like=walk)
        cls.bvh = os.path.join(cls.tmp, "small.bvh")
        small.save_bvh(cls.bvh)
        cls.input = mf.Motion.load_bvh(cls.bvh)  # what the CLI reads
        cls.threads = mf.get_num_threads()
        mf.set_num_threads(CLI_THREADS)

    @classmethod
    def tearDownClass(cls):
        mf.set_num_threads(cls.threads)
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def run_cli(self, task, *args):
        out = os.path.join(self.tmp, "%s-cli.bvh" % task)
        done = subprocess.run([self.cli, "--verbose", task, "--in", self.bvh, "--out", out] + list(args),
                              capture_output=True, text=True, timeout=120)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(out) as f:
            return f.read(), done.stderr

    def assert_same(self, python, cli_text):
        python_text = python.to_bvh_text()
        self.assertEqual(python_text.split("MOTION")[0], cli_text.split("MOTION")[0])
        a, b = motion_numbers(python_text), motion_numbers(cli_text)
        self.assertEqual(a.shape, b.shape)
        diff = float(np.abs(a - b).max())
        self.assertLessEqual(diff, 1e-6, "largest difference of the BVH numbers: %g" % diff)
        cli = mf.Motion.from_bvh_text(cli_text)
        np.testing.assert_allclose(python.rotations, cli.rotations, atol=1e-5)
        np.testing.assert_allclose(python.root_positions, cli.root_positions, atol=1e-5)
        return python_text == cli_text

    def test_inbetween_without_arguments_is_the_cli_default(self):
        keys = [0, 10, 20, 30]
        cli_text, log = self.run_cli("inbetween", "--keyframes", ",".join(map(str, keys)))
        method = re.search(r"method (\S+),", log).group(1)
        self.assertEqual(mf.default_method(), method)
        if os.path.isfile(os.path.join(os.path.dirname(mf.default_model_path()), "motionfield-twostage.mfm")):
            self.assertEqual(method, "nemf-detail")
        self.assertIn("model %s" % mf.default_model_path(), log)
        python = mf.inbetween(self.input, keys)
        np.testing.assert_array_equal(python.rotations[keys], self.input.rotations[keys])
        self.assert_same(python, cli_text)
        # Not plain interpolation (what Python did by default before).
        self.assertNotEqual(mf.inbetween(self.input, keys, method="interp").to_bvh_text(), python.to_bvh_text())

    def test_fill_and_resample_without_arguments_are_the_cli_defaults(self):
        cli_text, _ = self.run_cli("fill", "--gap", "5:25")
        self.assert_same(mf.fill(self.input, 5, 25), cli_text)
        cli_text, log = self.run_cli("resample", "--fps", "60")
        self.assertIn("model %s" % mf.default_model_path(), log)
        python = mf.resample(self.input, 60.0)
        self.assertEqual(python.frame_count, 61)
        self.assert_same(python, cli_text)
        self.assertEqual(mf.resample(self.input, 60.0, method="prior").to_bvh_text(), python.to_bvh_text())

    def test_an_iteration_budget_is_the_cli_flag(self):
        keys = [0, 10, 20, 30]
        cli_text, _ = self.run_cli("inbetween", "--keyframes", ",".join(map(str, keys)), "--max-iterations", "1")
        python = mf.inbetween(self.input, keys, max_iterations=1)
        self.assert_same(python, cli_text)
        self.assertNotEqual(python.to_bvh_text(), mf.inbetween(self.input, keys).to_bvh_text())
        solved = mf.solve(self.input, keys, max_iterations=1)  # the constrained path takes it too
        self.assertEqual(solved.motions[0].to_bvh_text(), python.to_bvh_text())


if __name__ == "__main__":
    unittest.main()
