"""The package's conventions: one version, type hints and numpy-style
docstrings on everything public, the motion first and the model by keyword,
the old positional forms still accepted with a DeprecationWarning, the
default model shared.

Named after test_motionfield.py on purpose (see test_same_as_cli.py).
"""

import inspect
import os
import pickle
import re
import typing
import unittest
import warnings

import numpy as np

import motionfield as mf

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.environ.get("MF_SOURCE_DIR", os.path.normpath(os.path.join(HERE, "..", "..")))
SAMPLE = os.path.join(SOURCE, "samples", "walk_keyframes.bvh")


def cmake_version():
    with open(os.path.join(SOURCE, "CMakeLists.txt")) as f:
        return re.search(r"project\(\s*motionfield\s+VERSION\s+([0-9.]+)", f.read()).group(1)


def public_callables():
    """(qualified name, function) of every public function and method."""
    for name in mf.__all__:
        obj = getattr(mf, name)
        if inspect.isfunction(obj):
            yield name, obj
        elif inspect.isclass(obj):
            if not issubclass(obj, tuple):  # NamedTuples: fields only
                init = obj.__dict__.get("__init__")
                if init is not None and not issubclass(obj, mf.Error):
                    yield name, obj  # the class documents its constructor
            for attr, member in vars(obj).items():
                if attr.startswith("_"):
                    continue
                if isinstance(member, (classmethod, staticmethod)):
                    member = member.__func__
                if inspect.isfunction(member):
                    yield "%s.%s" % (name, attr), member
            for attr, member in vars(mf._Handle).items():
                if not attr.startswith("_") and inspect.isfunction(member) and issubclass(obj, mf._Handle):
                    yield "%s.%s" % (name, attr), member


class VersionTest(unittest.TestCase):
    def test_one_version(self):
        self.assertEqual(mf.__version__, mf.version())
        self.assertEqual(mf.__version__, cmake_version())
        self.assertIn("__version__", mf.__all__)

    def test_py_typed(self):
        self.assertTrue(os.path.isfile(os.path.join(os.path.dirname(mf.__file__), "py.typed")))


class ModulesTest(unittest.TestCase):
    def test_public_names_are_the_package_s(self):
        # Defined in private modules, named motionfield.X: reprs, help() and
        # pickles (Dask sends errors between processes) say so.
        for name in mf.__all__:
            obj = getattr(mf, name)
            if inspect.isclass(obj) or inspect.isfunction(obj):
                self.assertEqual(obj.__module__, "motionfield", name)
                self.assertEqual(obj.__qualname__, name)
                typing.get_type_hints(obj)  # the annotations resolve in the package
        error = pickle.loads(pickle.dumps(mf.InvalidArgumentError("bad frame", mf.InvalidArgumentError.status)))
        self.assertIs(type(error), mf.InvalidArgumentError)
        self.assertEqual((str(error), error.status_name), ("bad frame", "MF_ERROR_INVALID_ARGUMENT"))
        self.assertEqual(pickle.loads(pickle.dumps(mf.Progress(3, 10, 0.5))), mf.Progress(3, 10, 0.5))
        self.assertIn(b"motionfield", pickle.dumps(mf.Progress(3, 10, 0.5)))


class DocumentationTest(unittest.TestCase):
    def test_every_public_function_has_type_hints(self):
        for name, fn in public_callables():
            target = fn.__init__ if inspect.isclass(fn) else fn
            hints = typing.get_type_hints(target)
            for p in inspect.signature(target).parameters.values():
                if p.name in ("self", "cls") or p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
                    continue
                self.assertIn(p.name, hints, "%s: no type hint on %s" % (name, p.name))
            self.assertIn("return", hints, "%s: no return type hint" % name)

    def test_every_public_function_has_a_numpy_docstring(self):
        checked = 0
        for name, fn in public_callables():
            doc = inspect.getdoc(fn) or ""
            target = fn.__init__ if inspect.isclass(fn) else fn
            params = [p for p in inspect.signature(target).parameters.values()
                      if p.name not in ("self", "cls") and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
            sections = (["Parameters"] if params else []) + ([] if inspect.isclass(fn) else ["Returns"]) + ["Raises"]
            for section in sections:
                self.assertRegex(doc, r"\n%s\n-{%d}\n" % (section, len(section)), "%s: no %s section" % (name, section))
            documented = doc.split("Parameters\n", 1)[-1].split("\nReturns\n", 1)[0].split("\nRaises\n", 1)[0]
            for p in params:
                self.assertRegex(documented, r"(^|\n|, )%s\b" % re.escape(p.name), "%s: %s not documented" % (name, p.name))
            self.assertNotIn("{task_", doc, name)
            checked += 1
        self.assertGreater(checked, 35)


class ArgumentOrderTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.walk = mf.Motion.load_bvh(SAMPLE)

    def test_motion_first_and_the_rest_by_keyword(self):
        for fn in (mf.inbetween, mf.fill, mf.resample, mf.renav, mf.describe_rig, mf.encode):
            params = list(inspect.signature(fn).parameters.values())
            self.assertIn(params[0].name, ("motion", "reference"), fn.__name__)
            self.assertEqual(params[0].annotation, "Motion", fn.__name__)
            self.assertEqual(inspect.signature(fn).parameters["model"].kind, inspect.Parameter.KEYWORD_ONLY,
                             fn.__name__)
        self.assertEqual(inspect.signature(mf.default_method).parameters["model"].kind, inspect.Parameter.KEYWORD_ONLY)

    def test_old_positional_forms_warn_and_still_work(self):
        keys = [0, 30, 60]
        new = mf.inbetween(self.walk, keys, method="interp").rotations
        with self.assertWarnsRegex(DeprecationWarning, r"inbetween\(\): giving method by position"):
            old = mf.inbetween(self.walk, keys, "interp").rotations
        np.testing.assert_array_equal(old, new)
        with self.assertWarns(DeprecationWarning):
            self.assertEqual(mf.fill(self.walk, 10, 20, "zerovel", None, 0).frame_count, 61)
        with self.assertWarns(DeprecationWarning):
            self.assertEqual(mf.resample(self.walk, 60.0, "interp").frame_count, 121)
        with self.assertRaisesRegex(TypeError, "multiple values for argument 'method'"):
            mf.inbetween(self.walk, keys, "interp", method="interp")
        with self.assertRaisesRegex(TypeError, "at most"):
            mf.resample(self.walk, 60.0, "interp", None, 0, None, None, None, "extra")
        with self.assertWarns(DeprecationWarning):
            self.assertEqual(mf.default_method(None), mf.default_method())
        names = ["Hips", "Head"]
        rot = np.tile(np.array([1, 0, 0, 0], np.float32), (3, 2, 1))
        with self.assertWarns(DeprecationWarning):
            m = mf.Motion.from_arrays(rot, np.zeros((3, 3)), 30.0, names, [-1, 0], [[0, 0, 0], [0, 0.5, 0]])
        self.assertEqual(m.joint_names, names)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            mf.Motion.from_arrays(rot, np.zeros((3, 3)), 30.0, joint_names=names, parents=[-1, 0],
                                  offsets=[[0, 0, 0], [0, 0.5, 0]])

    def test_old_model_first_forms_warn_and_still_work(self):
        model = mf.default_model()
        self.assertIsNotNone(model)
        with self.assertWarnsRegex(DeprecationWarning, r"describe_rig\(\): giving model by position"):
            old = mf.describe_rig(self.walk, model)
        self.assertEqual(old, mf.describe_rig(self.walk))
        clip = mf.Motion.from_arrays(self.walk.rotations[:40], self.walk.root_positions[:40], 30.0, model=model)
        with self.assertWarnsRegex(DeprecationWarning, r"encode\(model, motion\) is deprecated"):
            old = mf.encode(model, clip, 8)
        new = mf.encode(clip, model=model, hop=8)
        np.testing.assert_array_equal(old.local_latents, new.local_latents)
        np.testing.assert_array_equal(mf.encode(clip).local_latents, mf.encode(clip, model=model).local_latents)
        with self.assertRaises(TypeError):
            mf.encode(clip, model)
        with self.assertWarnsRegex(DeprecationWarning, r"renav\(\): giving model by position"):
            with self.assertRaisesRegex(mf.InvalidArgumentError, r"path must have shape \[points, 2\]"):
                mf.renav(self.walk, np.zeros((5, 3)), model)


class DefaultModelTest(unittest.TestCase):
    def test_the_default_model_is_loaded_once_and_only_when_needed(self):
        path = mf.default_model_path()
        self.assertIsNotNone(path)
        if not os.environ.get("MF_MODEL"):
            self.assertEqual(os.path.realpath(path),
                             os.path.realpath(os.path.join(SOURCE, "models", "motionfield-prior.mfm")))
        model = mf.default_model()
        self.assertIs(mf.default_model(), model)
        self.assertEqual(mf.default_method(), mf.default_method(model=model))
        self.assertEqual(mf.default_method(), "nemf-detail" if model.has_inbetweener("twostage") else "nemf")

    def test_a_method_that_needs_the_model_gets_the_default_one(self):
        walk = mf.Motion.load_bvh(SAMPLE)
        names = {m.name: m for m in mf.methods()}
        self.assertTrue(names["prior"].needs_model and names["prior"].resamples)
        np.testing.assert_array_equal(mf.resample(walk, 40.0, method="prior").rotations,
                                      mf.resample(walk, 40.0, method="prior", model=mf.default_model()).rotations)

    def test_a_missing_default_model_is_named(self):
        # In a child process: the default model is cached per path in this one.
        import subprocess
        import sys
        code = ("import motionfield as mf\n"
                "try:\n"
                "    mf.inbetween(mf.Motion.load_bvh(%r), [0, 60])\n"
                "except mf.FileError as e:\n"
                "    print(e)\n" % SAMPLE)
        env = dict(os.environ, MF_MODEL="/nonexistent/model.mfm")
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertIn("cannot load the default model: cannot open model file /nonexistent/model.mfm", done.stdout)


if __name__ == "__main__":
    unittest.main()
