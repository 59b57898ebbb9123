"""`python3 -m motionfield.dask` against `motionfield batch` on one jobs file.

A LocalCluster of 2 worker processes (one thread each) runs a small jobs file:
a few short jobs of every task, good and bad (bad lines the parser refuses,
and jobs that fail on the worker: a missing input, a missing directory, an
unknown method, an output that is the input, a keyframe out of range, an
unknown unit, a re-navigation method that does not exist, a missing and a bad
rig map, a negative frame rate). The outputs must be byte-identical to the CLI's on the same
file, and the messages (stderr lines, --json summaries without the timings)
the same, in line order, with the same exit code (both run each line through
the library's job runner, mf_job_runner).

Not named test_*.py: the capi_python test discovers those, and this one needs
python3-distributed; CTest runs it as python_dask_batch (tests/CMakeLists.txt)
with $MOTIONFIELD_LIBRARY and $MF_CLI set.
"""

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import motionfield as mf

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.environ.get("MF_SOURCE_DIR", os.path.normpath(os.path.join(HERE, "..", "..")))
SAMPLE = os.path.join(SOURCE, "samples", "walk_keyframes.bvh")
THREADS = "1"

GOOD = [
    {"id": "walk-inbetween", "task": "inbetween", "in": "walk.bvh", "out": "out/inbetween.bvh",
     "keyframes": [0, 20, 40, 60]},                                                    # default method, model
    {"task": "fill", "in": "walk.bvh", "out": "out/fill.bvh", "gap": [10, 30], "method": "interp"},
    {"task": "resample", "in": "walk.bvh", "out": "out/resample.bvh", "fps": 60},      # "prior"
    {"task": "renav", "in": "walk.bvh", "out": "out/renav.bvh", "path": "path.csv"},   # "nemf"
    {"id": 5, "task": "fill", "in": "walk.bvh", "out": "out/fill-keys.bvh", "keyframes": [0, 30, 60],
     "method": "zerovel", "units": "cm"},
    {"task": "fill", "in": "walk.bvh", "out": "out/constrained.bvh", "gap": [10, 40], "method": "interp",
     "constraints": {"keys": [{"frame": 25, "joints": ["Head"]}], "contacts": [{"joint": "Foot_L", "first": 30,
                                                                               "last": 35}]},
     "report": "out/constrained-report.json"},                                       # docs/CONSTRAINTS.md
    {"task": "fill", "in": "walk.bvh", "out": "out/trajectory.bvh", "gap": [15, 45], "method": "nemf",
     "trajectory": "t.csv", "report": "out/trajectory-report.json"},                 # a trajectory CSV
    {"task": "fill", "in": "walk.bvh", "out": "out/budget.bvh", "gap": [10, 40], "method": "nemf",
     "max_iterations": 2},                                                           # an iteration budget
]
REPORTS = ["constrained-report.json", "trajectory-report.json"]
BAD_LINES = [
    '{"id": 7, "task": "fill", "in": "walk.bvh", "out": "out/bad-gap.bvh", "gap": [10]}',
    '{"task": "fill",}',
    '{"task": "warp", "in": "walk.bvh", "out": "x.bvh"}',
    '{"task": "inbetween", "in": "walk.bvh", "out": "out/fill.bvh", "keyframes": [0, 60]}',
    '{"task": "resample", "in": "-", "out": "y.bvh", "fps": 30}',
    '[1, 2]',
    '{"task": "inbetween", "in": "walk.bvh", "out": "k.bvh", "keyframes": [0, 1.5]}',
    '{"task": "renav", "in": "walk.bvh", "out": "r.bvh", "path": "p.csv", "polyline": "q.csv"}',
    '{"task": "resample", "in": "walk.bvh", "out": "u.bvh", "fps": 30, "units": -1}',
    '{"task": "fill", "in": "walk.bvh", "out": "z.bvh", "gap": [1, 5], "gap": [2, 6]}',
    '{"task": "fill", "in": "walk.bvh", "out": "z.bvh", "gap": [1e400, 5]}',
    '{"task": "inbetween", "in": "walk.bvh", "out": "z.bvh", "keyframes": [0, 3000000000]}',
    '{"task": "inbetween", "in": "walk.bvh", "out": "z.bvh", "keyframes": [0, 60], "constraints": 3}',
    '{"task": "inbetween", "in": "walk.bvh", "out": "z.bvh", "keyframes": [0, 60], "alternatives": 17}',
    '{"task": "fill", "in": "walk.bvh", "out": "z.bvh", "gap": [15, 45], "trajectory": 3}',
    '{"task": "fill", "in": "walk.bvh", "out": "z.bvh", "gap": [15, 45], "max_iterations": -1}',
]
WORKER_FAILURES = [
    {"task": "fill", "in": "missing.bvh", "out": "out/missing.bvh", "gap": [1, 5]},
    {"task": "fill", "in": "walk.bvh", "out": "nodir/x.bvh", "gap": [1, 5]},
    {"task": "inbetween", "in": "walk.bvh", "out": "out/m.bvh", "keyframes": [0, 60], "method": "nope"},
    {"task": "fill", "in": "walk.bvh", "out": "walk.bvh", "gap": [1, 5], "method": "interp"},
    {"id": "far", "task": "inbetween", "in": "walk.bvh", "out": "out/k.bvh", "keyframes": [0, 100],
     "method": "interp"},
    {"task": "resample", "in": "walk.bvh", "out": "out/u2.bvh", "fps": 30, "units": "furlong"},
    {"task": "renav", "in": "walk.bvh", "out": "out/r1.bvh", "path": "path.csv", "method": "interp"},
    {"task": "fill", "in": "walk.bvh", "out": "out/f1.bvh", "gap": [2, 5], "rig_map": "missing-map.json"},
    {"task": "fill", "in": "walk.bvh", "out": "out/f2.bvh", "gap": [2, 5], "rig_map": "notamap.json", "method": "nemf"},
    {"task": "resample", "in": "walk.bvh", "out": "out/s.bvh", "fps": -5},
    {"task": "inbetween", "in": "walk.bvh", "out": "out/c.bvh", "keyframes": [0, 60], "method": "interp",
     "constraints": {"keys": [{"frame": 30, "joints": ["Tail"]}]}},
    {"task": "fill", "in": "walk.bvh", "out": "out/t1.bvh", "gap": [15, 45], "method": "interp", "trajectory": "t.csv"},
    {"task": "fill", "in": "walk.bvh", "out": "out/t2.bvh", "gap": [15, 45], "method": "nemf", "trajectory": "none.csv"},
    # A report naming its own output, another job's output, the input (docs/RELIABILITY.md, "Outputs and clients").
    {"task": "inbetween", "in": "walk.bvh", "out": "out/r2.bvh", "keyframes": [0, 60], "method": "interp",
     "report": "out/r2.bvh"},
    {"task": "inbetween", "in": "walk.bvh", "out": "out/r3.bvh", "keyframes": [0, 60], "method": "interp",
     "report": "out/./fill.bvh"},
    {"task": "inbetween", "in": "walk.bvh", "out": "out/r4.bvh", "keyframes": [0, 60], "method": "interp",
     "report": "walk.bvh"},
]


def jobs_text():
    lines = [json.dumps(j) for j in GOOD[:2]] + [""] + [json.dumps(j) for j in GOOD[2:]]
    lines += BAD_LINES + [json.dumps(j) for j in WORKER_FAILURES]
    return "\n".join(lines) + "\n"


def set_up_dir(path):
    os.makedirs(os.path.join(path, "out"))
    shutil.copy(SAMPLE, os.path.join(path, "walk.bvh"))
    with open(os.path.join(path, "path.csv"), "w") as f:
        f.write("x,z\n" + "".join("%.4f,%.4f\n" % (0.3 * (i / 30.0) ** 2, 0.04 * i) for i in range(30)))
    with open(os.path.join(path, "t.csv"), "w") as f:  # 15 cm left of a straight walk along +Z, facing +Z
        f.write("frame,x,z,forward_x,forward_z\n" + "".join(
            "%d,%.4f,%.4f,0,1\n" % (i, 15 * math.sin(math.pi * (i - 14) / 32), -60 + 3.24 * i) for i in range(15, 45)))
    with open(os.path.join(path, "notamap.json"), "w") as f:
        f.write('{"a": 1}\n')
    with open(os.path.join(path, "jobs.jsonl"), "w") as f:
        f.write(jobs_text())


def without_timings(stdout):
    out = []
    for line in stdout.splitlines():
        j = json.loads(line)
        j.pop("timings_ms", None)
        out.append(j)
    return out


class DaskBatchTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.cli = os.environ.get("MF_CLI") or os.path.join(SOURCE, "build", "cli", "motionfield")
        if not os.access(cls.cli, os.X_OK):
            raise AssertionError("no CLI at %s (set MF_CLI; CTest does)" % cls.cli)
        cls.tmp = tempfile.mkdtemp(prefix="mf-dask-test-")
        cls.cli_dir, cls.dask_dir = os.path.join(cls.tmp, "cli"), os.path.join(cls.tmp, "dask")
        set_up_dir(cls.cli_dir)
        set_up_dir(cls.dask_dir)
        # --jobs 2: the CLI loads the model before the jobs, as the Dask workers do.
        cls.cli_run, cls.dask_run = run_both(cls.cli, cls.tmp, ["--json"], ["--jobs", "2"])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_same_exit_code(self):
        self.assertEqual(self.cli_run.returncode, 2, self.cli_run.stderr)
        self.assertEqual(self.dask_run.returncode, 2, self.dask_run.stderr)

    def test_outputs_are_byte_identical(self):
        written = sorted(os.listdir(os.path.join(self.cli_dir, "out")))
        self.assertEqual(written, sorted([os.path.basename(j["out"]) for j in GOOD] + REPORTS))
        self.assertEqual(sorted(os.listdir(os.path.join(self.dask_dir, "out"))), written)
        for name in written:
            with open(os.path.join(self.cli_dir, "out", name), "rb") as a, \
                    open(os.path.join(self.dask_dir, "out", name), "rb") as b:
                self.assertTrue(a.read() == b.read(), "out/%s differs from the CLI's" % name)
        with open(SAMPLE, "rb") as a, open(os.path.join(self.dask_dir, "walk.bvh"), "rb") as b:
            self.assertEqual(a.read(), b.read(), "the job whose output is its input replaced it")

    def test_good_jobs_succeed_and_bad_ones_are_reported(self):
        summaries = [json.loads(line) for line in self.dask_run.stdout.splitlines()]
        self.assertEqual(len(summaries), len(GOOD) + len(BAD_LINES) + len(WORKER_FAILURES))
        self.assertEqual([s["status"] for s in summaries],
                         ["ok"] * len(GOOD) + ["error"] * (len(BAD_LINES) + len(WORKER_FAILURES)))
        self.assertEqual([s["line"] for s in summaries[:4]], [1, 2, 4, 5])  # line 3 is blank
        self.assertEqual(summaries[0]["method"], mf.default_method())
        first_bad = len(GOOD) + 2  # after the good jobs and the blank line
        self.assertIn('motionfield: jobs.jsonl line %d (id 7): error: "gap" must be an array of two integers'
                      % first_bad, self.dask_run.stderr)
        self.assertIn("jobs.jsonl line %d: error: cannot write nodir/x.bvh: directory nodir does not exist"
                      % (first_bad + len(BAD_LINES) + 1), self.dask_run.stderr)
        self.assertTrue(self.dask_run.stderr.endswith("motionfield: batch jobs.jsonl: %d jobs, %d ok, %d failed\n" % (
            len(summaries), len(GOOD), len(summaries) - len(GOOD))), self.dask_run.stderr)

    def test_same_messages_as_the_cli(self):
        self.assertEqual(without_timings(self.dask_run.stdout), without_timings(self.cli_run.stdout))
        self.assertEqual(self.dask_run.stderr, self.cli_run.stderr)


def run_both(cli, directory, options, cli_batch_options=()):
    """(CLI run, Dask run) of jobs.jsonl with the global `options`, in directory/cli and directory/dask:
    `motionfield --threads 1 OPTIONS batch CLI_BATCH_OPTIONS jobs.jsonl` and
    `python3 -m motionfield.dask --workers 2 --threads 1 OPTIONS jobs.jsonl`."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in [os.path.dirname(os.path.dirname(mf.__file__)),
                                                                    os.environ.get("PYTHONPATH")] if p),
               MOTIONFIELD_LIBRARY=mf.library_path())
    cli_run = subprocess.run([cli, "--threads", THREADS] + list(options) + ["batch"] + list(cli_batch_options)
                             + ["jobs.jsonl"], cwd=os.path.join(directory, "cli"), capture_output=True, text=True,
                             timeout=300)
    dask_run = subprocess.run([sys.executable, "-m", "motionfield.dask", "--workers", "2", "--threads", THREADS]
                              + list(options) + ["jobs.jsonl"], cwd=os.path.join(directory, "dask"),
                              capture_output=True, text=True, timeout=300, env=env)
    return cli_run, dask_run


class LoadWarningTest(unittest.TestCase):
    """A transformer file next to the model that does not load: the CLI warns
    once, on the first job that names no method; so does the Dask run."""

    def test_the_load_warning_goes_to_the_first_job_without_a_method(self):
        cli = os.environ.get("MF_CLI") or os.path.join(SOURCE, "build", "cli", "motionfield")
        models = os.path.join(SOURCE, "models")
        tmp = tempfile.mkdtemp(prefix="mf-dask-warn-")
        self.addCleanup(shutil.rmtree, tmp, True)
        for side in ("cli", "dask"):
            d = os.path.join(tmp, side)
            os.makedirs(os.path.join(d, "m"))
            os.makedirs(os.path.join(d, "out"))
            shutil.copy(SAMPLE, os.path.join(d, "walk.bvh"))
            for name in ("motionfield-prior.mfm", "motionfield-rig.json"):
                shutil.copy(os.path.join(models, name), os.path.join(d, "m", name))
            with open(os.path.join(models, "motionfield-twostage.mfm"), "rb") as f, \
                    open(os.path.join(d, "m", "motionfield-twostage.mfm"), "wb") as g:
                g.write(f.read(1000))  # truncated
            with open(os.path.join(d, "jobs.jsonl"), "w") as f:
                f.write('{"task": "fill", "in": "walk.bvh", "out": "out/a.bvh", "gap": [2, 5], "method": "interp"}\n'
                        '{"task": "fill", "in": "walk.bvh", "out": "out/b.bvh", "gap": [2, 5]}\n'
                        '{"task": "fill", "in": "walk.bvh", "out": "out/c.bvh", "gap": [2, 8]}\n')
        cli_run, dask_run = run_both(cli, tmp, ["--model", "m/motionfield-prior.mfm"])
        self.assertEqual((cli_run.returncode, dask_run.returncode), (0, 0), cli_run.stderr + dask_run.stderr)
        self.assertRegex(dask_run.stderr, r"^motionfield: jobs.jsonl line 2: warning: motionfield-twostage.mfm next to "
                                          r"the model did not load.*truncated")
        self.assertEqual(dask_run.stderr.count("warning"), 1, dask_run.stderr)
        self.assertEqual(dask_run.stderr, cli_run.stderr)
        for name in ("a.bvh", "b.bvh", "c.bvh"):
            with open(os.path.join(tmp, "cli", "out", name), "rb") as a, \
                    open(os.path.join(tmp, "dask", "out", name), "rb") as b:
                self.assertTrue(a.read() == b.read(), "out/%s differs from the CLI's" % name)


if __name__ == "__main__":
    unittest.main()
