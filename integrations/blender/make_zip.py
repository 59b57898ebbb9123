#!/usr/bin/env python3
"""Builds the installable Blender add-on zip.

    python3 integrations/blender/make_zip.py OUT.zip [--library build/capi/libmotionfield.so.0] [--no-bundle]

The zip holds motionfield_blender/ and, in motionfield_blender/_vendor/, the
motionfield Python package as ``pip install ./python`` makes it (offline,
python/setup.py): with the built library and the bundled models inside it
(``--library``, by default the checkout's build/capi/libmotionfield.so.0),
or pure Python with ``--no-bundle`` (the library is then found through the
add-on's "Library" preference, $MOTIONFIELD_LIBRARY or the system's library
path). The library links no libtorch; it needs Debian's Ceres, OpenBLAS,
assimp and tinygltf: the zip works on machines with the same packages
(scripts/install-deps.sh).
"""

import argparse
import os
import subprocess
import sys
import tempfile
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
ADDON = os.path.join(HERE, "motionfield_blender")


def vendor_package(target, library):
    """pip installs ./python into `target` (the package's own bundling)."""
    env = dict(os.environ)
    if library:
        env.update(MOTIONFIELD_LIBRARY=os.path.abspath(library), MOTIONFIELD_BUNDLE="1")
    else:
        env["MOTIONFIELD_BUNDLE"] = "0"
    with tempfile.TemporaryDirectory() as build:  # keep pip's build files out of the checkout
        subprocess.run([sys.executable, "-m", "pip", "install", "--no-index", "--no-build-isolation", "--no-deps",
                        "--no-cache-dir", "--disable-pip-version-check", "--quiet", "--target", target, "."],
                       cwd=os.path.join(ROOT, "python"), env=dict(env, TMPDIR=build), check=True)


def add_tree(z, src, arc):
    for d, dirs, files in os.walk(src):
        dirs[:] = [x for x in dirs if x != "__pycache__" and not x.endswith((".dist-info", ".egg-info"))]
        for f in sorted(files):
            if f.endswith(".pyc"):
                continue
            path = os.path.join(d, f)
            z.write(path, os.path.join(arc, os.path.relpath(path, src)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="the zip to write")
    ap.add_argument("--library", default=os.path.join(ROOT, "build", "capi", "libmotionfield.so.0"),
                    help="libmotionfield.so to bundle (default: %(default)s)")
    ap.add_argument("--no-bundle", action="store_true", help="bundle neither the library nor the models")
    a = ap.parse_args()
    library = None if a.no_bundle else a.library
    if library and not os.path.isfile(library):
        sys.exit("make_zip.py: no library at %s (build it first: make build, or give --library / --no-bundle)"
                 % library)
    with tempfile.TemporaryDirectory() as tmp:
        vendor_package(tmp, library)
        with zipfile.ZipFile(a.out, "w", zipfile.ZIP_DEFLATED) as z:
            add_tree(z, ADDON, "motionfield_blender")
            add_tree(z, os.path.join(tmp, "motionfield"), "motionfield_blender/_vendor/motionfield")
    print("wrote %s (%s)" % (a.out, "library and models bundled from " + library if library else "pure Python"))


if __name__ == "__main__":
    main()
