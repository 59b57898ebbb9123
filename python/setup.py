"""Build script of the motionfield Python package (metadata in pyproject.toml).

    pip install --no-index --no-build-isolation ./python

What it adds to pyproject.toml:

- the version: ``project(motionfield VERSION x.y.z)`` of ../CMakeLists.txt, the
  one place it is written (the C header is checked against it, and
  ``motionfield.__version__`` is the loaded library's);
- the bundle: when it finds a built libmotionfield.so.0 ($MOTIONFIELD_LIBRARY,
  else the source tree's build/capi/), it copies it into the package as
  ``motionfield/lib/libmotionfield.so.0`` and the source tree's models
  (motionfield-prior.mfm, every transformer next to it and the rig anatomy) as
  ``motionfield/share/motionfield/``: the package is then a small install
  prefix of its own, where the library finds its default model as it does in
  a CMake install tree (<prefix>/share/motionfield next to <prefix>/lib).
  $MOTIONFIELD_BUNDLE: "auto" (the default: bundle what is found), "1"
  (fail if no library is found), "0" (a pure-Python package that finds the
  library at run time: $MOTIONFIELD_LIBRARY, a CMake install tree, the system's
  library path). $MOTIONFIELD_BUNDLE_MODELS=0 bundles the library without the
  models (the library then finds them through $MF_MODEL or the source tree).
"""

import atexit
import os
import re
import shutil
import tempfile

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
MODEL_FILES = ("motionfield-prior.mfm", "motionfield-twostage.mfm", "motionfield-citl.mfm", "motionfield-keyframe.mfm",
               "motionfield-rig.json")


def project_version():
    cmake = os.path.join(ROOT, "CMakeLists.txt")
    if os.path.isfile(cmake):
        with open(cmake, encoding="utf-8") as f:
            m = re.search(r"project\(\s*motionfield\s+VERSION\s+([0-9][0-9.]*)", f.read())
        if m:
            return m.group(1)
    pkg_info = os.path.join(HERE, "PKG-INFO")  # an sdist
    if os.path.isfile(pkg_info):
        with open(pkg_info, encoding="utf-8") as f:
            m = re.search(r"^Version: (\S+)$", f.read(), re.M)
        if m:
            return m.group(1)
    raise RuntimeError("cannot find the version: %s has no project(motionfield VERSION ...)" % cmake)


def bundled_library():
    """The built library to bundle, or None."""
    choice = os.environ.get("MOTIONFIELD_BUNDLE", "auto")
    if choice not in ("auto", "0", "1"):
        raise RuntimeError("MOTIONFIELD_BUNDLE must be auto, 0 or 1, not %r" % choice)
    if choice == "0":
        return None
    env = os.environ.get("MOTIONFIELD_LIBRARY")
    candidates = [env] if env else [os.path.join(ROOT, "build", "capi", "libmotionfield.so.0")]
    for path in candidates:
        if os.path.isfile(path):
            return os.path.realpath(path)
    if choice == "1":
        raise RuntimeError("MOTIONFIELD_BUNDLE=1 and no library at %s (build it first: make build)" % candidates[0])
    return None


def bundled_models():
    if os.environ.get("MOTIONFIELD_BUNDLE_MODELS", "1") == "0":
        return []
    models = os.path.join(ROOT, "models")
    if not os.path.isfile(os.path.join(models, MODEL_FILES[0])):
        return []
    return [os.path.join(models, f) for f in MODEL_FILES if os.path.isfile(os.path.join(models, f))]


LIBRARY = bundled_library()


class BuildPy(build_py):
    """build_py plus the bundled library and models."""

    def run(self):
        super().run()
        if LIBRARY is None:
            return
        package = os.path.join(self.build_lib, "motionfield")
        self.mkpath(os.path.join(package, "lib"))
        self.copy_file(LIBRARY, os.path.join(package, "lib", "libmotionfield.so.0"), preserve_mode=True)
        share = os.path.join(package, "share", "motionfield")
        for path in bundled_models():
            self.mkpath(share)
            self.copy_file(path, os.path.join(share, os.path.basename(path)))


class BinaryDistribution(Distribution):
    """A platform wheel when it carries the library."""

    def has_ext_modules(self):
        return LIBRARY is not None


# Build in a temporary directory, not in python/build: a stale bundle of an
# earlier build never finds its way into a new one, and the source tree stays clean.
_build_base = tempfile.mkdtemp(prefix="motionfield-build-")
atexit.register(shutil.rmtree, _build_base, True)

setup(
    version=project_version(),
    cmdclass={"build_py": BuildPy},
    distclass=BinaryDistribution,
    options={"build": {"build_base": _build_base}, "egg_info": {"egg_base": _build_base}},
)
