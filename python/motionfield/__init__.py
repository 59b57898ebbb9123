"""motionfield from Python: a learned human-motion prior for keyframe
in-betweening, gap filling, transitions between two clips, resampling and
re-navigation along a new path.

A pure ctypes binding of libmotionfield.so's C API (no compiled extension):
numpy arrays in and out, exceptions from the C status codes. Conventions are
those of the C API: metres, seconds, Y up, quaternions (w, x, y, z); arrays
are float32, row-major:

    rotations        [frames, joints, 4]
    root_positions   [frames, 3]
    offsets          [joints, 3]
    global_positions [frames, joints, 3]

Example::

    import motionfield as mf
    walk = mf.Motion.load_bvh("samples/walk_keyframes.bvh")
    filled = mf.inbetween(walk, [0, 15, 30, 45, 60])   # the CLI's default method
    mf.resample(filled, 60.0).save_bvh("walk60.bvh")
    run = mf.Motion.load("character.glb", animation="Run")  # BVH, glTF or FBX

Every task takes the motion first and everything else by keyword. Without
``model=`` a task uses the default model, exactly as the CLI does without
``--model``: ``$MF_MODEL``, else the model installed next to the library
(``<prefix>/share/motionfield/motionfield-prior.mfm``; for a bundled library
that is inside this package), else the source tree's
``models/motionfield-prior.mfm``; the transformer in-betweeners next to it
are loaded with it. It is loaded once, on first use, and only when the
method is the default one or needs a model. Without ``method=`` a task uses
the CLI's default method (``default_method()``: "nemf-detail" with the
bundled model), so ``inbetween(motion, keys)`` gives what ``motionfield
inbetween --in ... --keyframes ...`` gives.

Any humanoid rig works with every task, in its own unit (detected from the leg
length, or ``Motion.load_bvh(path, units="m")``) and frame rate: methods that
need the model retarget it to the model's rig and back. ``describe_rig(motion)``
shows the map found; ``rig_map=`` (a dict, a JSON file or JSON text) on the
tasks overrides it.

The library is found through ``$MOTIONFIELD_LIBRARY``, then inside this
package (a bundled copy), then the CMake install tree this package was
installed with, then a build tree of the source checkout, then the system's
library path (see ``library_path()``). Tasks release the GIL: several Python
threads may run them at once on one shared Model.
"""

from __future__ import annotations

# The modules are private: what is public is a name of the package, in __all__
# or one of the type aliases below.
from ._constraints import Constraints, Solution, solve
from ._encoding import Encoding, encode
from ._errors import (BufferTooSmallError, CancelledError, Error, FileError, InternalError, InvalidArgumentError,
                      ModelError, OutOfMemoryError, UnsupportedError)
from ._library import (Method, abi_version, find_method, get_num_threads, library_path, methods, printable_text,
                       set_num_threads, version)
from ._model import Model, default_method, default_model, default_model_path
from ._motion import Motion, length_unit_scale
from ._outputs import OutputSet
from ._tasks import (CancelToken, Progress, describe_rig, fill, inbetween, load_path_csv, renav, resample,
                     resample_frame_count)
from ._transition import Transition, transition

# The type aliases of the signatures.
from ._args import FloatArray as FloatArray, PathLike as PathLike, RigMap as RigMap
from ._constraints import PartialKey as PartialKey, Target as Target
from ._tasks import ProgressCallback as ProgressCallback

# The modules' shared helpers, importable from the package as they were when it
# was one module (tests/test_package.py uses _Handle).
from . import _capi as _c
from ._args import (_float_arg as _float_arg, _float_array as _float_array, _instance_arg as _instance_arg,
                    _int_arg as _int_arg, _int_list as _int_list, _keywords_after as _keywords_after,
                    _number_text as _number_text, _rig_map_args as _rig_map_args, _str_arg as _str_arg)
from ._encoding import _codec_options as _codec_options
from ._errors import _check as _check
from ._handles import (_f32_ptr as _f32_ptr, _Handle as _Handle, _read_floats as _read_floats,
                       _read_string as _read_string, _Skeletal as _Skeletal)
from ._library import _methods_by_name as _methods_by_name
from ._model import _needs_model as _needs_model, _required_model as _required_model, _task_model as _task_model
from ._motion import _bvh_options as _bvh_options, _gltf_options as _gltf_options, _units_scale as _units_scale
from ._tasks import _task_doc as _task_doc, _TaskCall as _TaskCall

# The other names the package held when it was one module. The typing names
# are needed: typing.get_type_hints() of a public class resolves its
# annotations here (its __module__, see below).
import ctypes
import functools
import inspect
import json
import math
import numbers
import os
import threading
import warnings
from typing import Any, Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple, Type, TypeVar, Union

import numpy as np
import numpy.typing as npt

__all__ = [
    "__version__",
    "Error", "InvalidArgumentError", "BufferTooSmallError", "FileError", "ModelError", "CancelledError",
    "InternalError", "UnsupportedError", "OutOfMemoryError",
    "version", "abi_version", "library_path", "set_num_threads", "get_num_threads",
    "Method", "methods", "find_method", "default_method", "default_model_path", "default_model",
    "printable_text",
    "Model", "Motion", "CancelToken", "Progress", "Encoding", "OutputSet",
    "inbetween", "fill", "resample", "resample_frame_count", "encode",
    "Constraints", "Solution", "solve", "Transition", "transition",
    "renav", "load_path_csv", "describe_rig", "length_unit_scale",
]

#: The package's version: the loaded library's (one source of truth, CMakeLists.txt's project(VERSION)).
__version__: str = version()

# The public classes and functions are motionfield's, wherever they are
# defined: their reprs, help(), pickles (Dask sends errors and results between
# processes) and type hints name motionfield.X, as they always have.
for _name in __all__:
    _obj = globals()[_name]
    if isinstance(_obj, type) or inspect.isfunction(_obj):
        _obj.__module__ = __name__
del _name, _obj
