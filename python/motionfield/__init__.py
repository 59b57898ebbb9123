"""motionfield from Python: a learned human-motion prior for keyframe
in-betweening, gap filling, resampling and re-navigation along a new path.

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

from . import _capi as _c

__all__ = [
    "__version__",
    "Error", "InvalidArgumentError", "BufferTooSmallError", "FileError", "ModelError", "CancelledError",
    "InternalError", "UnsupportedError", "OutOfMemoryError",
    "version", "abi_version", "library_path", "set_num_threads", "get_num_threads",
    "Method", "methods", "find_method", "default_method", "default_model_path", "default_model",
    "printable_text",
    "Model", "Motion", "CancelToken", "Progress", "Encoding", "OutputSet",
    "inbetween", "fill", "resample", "resample_frame_count", "encode",
    "Constraints", "Solution", "solve",
    "renav", "load_path_csv", "describe_rig", "length_unit_scale",
]

#: A file path: a string or an os.PathLike.
PathLike = Union[str, "os.PathLike[str]"]
#: A rig_map= argument: a dict {user joint: model joint or None}, a JSON file's path or JSON text.
RigMap = Union[Dict[str, Optional[str]], str, "os.PathLike[str]"]
#: A progress callback: gets a Progress, returns True to cancel the task.
ProgressCallback = Callable[["Progress"], Optional[bool]]
FloatArray = npt.NDArray[np.float32]

_F = TypeVar("_F", bound=Callable[..., Any])

# ------------------------------------------------------------------ errors


class Error(Exception):
    """A motionfield call failed.

    Attributes
    ----------
    status : int
        The C status code (MF_ERROR_*).
    status_name : str
        Its name, e.g. "MF_ERROR_INVALID_ARGUMENT".
    """

    status: Optional[int] = None

    def __init__(self, message: str, status: Optional[int] = None) -> None:
        super().__init__(message)
        if status is not None:
            self.status = status

    @property
    def status_name(self) -> str:
        """The name of the status code, e.g. "MF_ERROR_IO"."""
        return _c.mf_status_name(self.status).decode()


class InvalidArgumentError(Error, ValueError):
    """Bad input (MF_ERROR_INVALID_ARGUMENT); also a ValueError."""

    status = _c.ERROR_INVALID_ARGUMENT


class BufferTooSmallError(Error):
    """MF_ERROR_BUFFER_TOO_SMALL (the package sizes its buffers, so only on a bug)."""

    status = _c.ERROR_BUFFER_TOO_SMALL


class FileError(Error, OSError):
    """A file cannot be read or written (MF_ERROR_IO); also an OSError."""

    status = _c.ERROR_IO


class ModelError(Error):
    """The model is missing, not a model file, or lacks what the method needs (MF_ERROR_MODEL)."""

    status = _c.ERROR_MODEL


class CancelledError(Error):
    """The task was cancelled by its progress callback or its CancelToken (MF_ERROR_CANCELLED)."""

    status = _c.ERROR_CANCELLED


class InternalError(Error):
    """A bug in the library (MF_ERROR_INTERNAL)."""

    status = _c.ERROR_INTERNAL


class UnsupportedError(Error):
    """The operation is not supported (MF_ERROR_UNSUPPORTED)."""

    status = _c.ERROR_UNSUPPORTED


class OutOfMemoryError(Error, MemoryError):
    """MF_ERROR_OUT_OF_MEMORY; also a MemoryError."""

    status = _c.ERROR_OUT_OF_MEMORY


_ERRORS = {cls.status: cls for cls in (InvalidArgumentError, BufferTooSmallError, FileError, ModelError,
                                       CancelledError, InternalError, UnsupportedError, OutOfMemoryError)}


def _check(status: int) -> None:
    if status == _c.OK:
        return
    message = _c.mf_last_error_message().decode("utf-8", "replace")
    raise _ERRORS.get(status, Error)(message, status)


# ------------------------------------------------------------------ arguments
# Every argument is checked here before it crosses into C, as the CLI checks
# its own (docs/RELIABILITY.md, "Outputs and clients"): TypeError for a wrong
# type, InvalidArgumentError (a ValueError) for a wrong value, integers in
# range (ctypes would wrap 2**32 + 30 around to 30), frames integral (30.5 is
# no frame) and NaN and infinities named as such.

_INT32_MIN, _INT32_MAX = -2**31, 2**31 - 1


def _number_text(value: float) -> str:
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return repr(value)


def _int_arg(value: Any, what: str, low: int = _INT32_MIN, high: int = _INT32_MAX) -> int:
    """`value` as an int in [low, high]: an integer, or a float with an integral value."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError("%s must be an integer, not bool" % what)
    if isinstance(value, numbers.Integral):
        v = int(value)
    elif isinstance(value, numbers.Real):
        f = float(value)
        if not math.isfinite(f) or f != math.floor(f):
            raise InvalidArgumentError("%s must be an integer, not %s" % (what, _number_text(f)))
        v = int(f)
    else:
        raise TypeError("%s must be an integer, not %s" % (what, type(value).__name__))
    if not low <= v <= high:
        raise InvalidArgumentError("%s must be between %d and %d, not %d" % (what, low, high, v))
    return v


def _int_list(values: Any, what: str, low: int = _INT32_MIN, high: int = _INT32_MAX) -> npt.NDArray[np.int32]:
    """A sequence (or array) of _int_arg values as a contiguous int32 array."""
    if isinstance(values, np.ndarray):
        items = values.reshape(-1).tolist()
    elif isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        raise TypeError("%s must be a sequence of integers, not %s" % (what, type(values).__name__))
    else:
        items = list(values)
    out = np.empty(len(items), dtype=np.int32)
    for i, v in enumerate(items):
        out[i] = _int_arg(v, "%s item %d" % (what, i), low, high)
    return out


def _float_arg(value: Any, what: str) -> float:
    """A real number (NaN and infinities are the library's to refuse, by name)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError("%s must be a number, not %s" % (what, type(value).__name__))
    return float(value)


def _str_arg(value: Any, what: str, optional: bool = False) -> Optional[str]:
    if value is None and optional:
        return None
    if not isinstance(value, str):
        raise TypeError("%s must be a str, not %s" % (what, type(value).__name__))
    if "\0" in value:
        raise InvalidArgumentError("%s contains a NUL character, which no name can hold" % what)
    return value


def _instance_arg(value: Any, cls: Type[Any], what: str, optional: bool = False) -> Any:
    if (value is None and optional) or isinstance(value, cls):
        return value
    raise TypeError("%s must be a %s%s, not %s" % (what, cls.__name__, " or None" if optional else "",
                                                    type(value).__name__))


# ------------------------------------------------------------------ helpers


def _f32_ptr(a: np.ndarray) -> Any:
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_float))


def _read_floats(getter: Any, handle: Any, shape: Tuple[int, ...]) -> FloatArray:
    needed = ctypes.c_size_t(0)
    _check(getter(handle, None, 0, ctypes.byref(needed)))
    out = np.empty(needed.value, dtype=np.float32)
    _check(getter(handle, _f32_ptr(out), out.size, ctypes.byref(needed)))
    return out.reshape(shape)


def _read_string(getter: Any, *args: Any) -> str:
    needed = ctypes.c_size_t(0)
    _check(getter(*args, None, 0, ctypes.byref(needed)))
    buf = ctypes.create_string_buffer(needed.value)
    _check(getter(*args, buf, needed.value, ctypes.byref(needed)))
    return buf.value.decode("utf-8")


def _float_array(a: npt.ArrayLike, shape_tail: Tuple[int, ...], what: str) -> FloatArray:
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.ndim != 1 + len(shape_tail) or tuple(a.shape[1:]) != tuple(shape_tail):
        raise InvalidArgumentError("%s must have shape [N, %s], not %s" %
                                   (what, ", ".join(map(str, shape_tail)), list(a.shape)))
    return a


def _bvh_options(length_scale: Optional[float]) -> Any:
    o = _c.MfBvhOptions()
    _check(_c.mf_bvh_options_init(ctypes.byref(o)))
    if length_scale is not None:
        o.length_scale = float(length_scale)
    return o


_GLTF_FORMATS = {None: 0, "auto": 0, "glb": 1, "gltf": 2}  # MF_GLTF_AUTO, MF_GLTF_BINARY, MF_GLTF_EMBEDDED


def _gltf_options(format: Optional[str]) -> Any:
    if format not in _GLTF_FORMATS:
        raise InvalidArgumentError("format must be None, 'auto', 'glb' or 'gltf', not %r" % (format,))
    o = _c.MfGltfOptions()
    _check(_c.mf_gltf_options_init(ctypes.byref(o)))
    o.format = _GLTF_FORMATS[format]
    return o


def _units_scale(units: Union[str, float, None], length_scale: Optional[float]) -> Optional[float]:
    """Metres per file unit for reading: None or "auto" -> None (detected), a
    unit name ("cm", "m", "mm", "in", "ft", "asf") or a number."""
    if length_scale is not None:
        if units is not None:
            raise InvalidArgumentError("give units or length_scale, not both")
        return length_scale
    if units is None or units == "auto":
        return None
    if isinstance(units, str):
        return length_unit_scale(units)
    return float(units)


def _rig_map_args(rig_map: Optional[RigMap]) -> Tuple[Optional[str], Optional[str]]:
    """(JSON text, file path) of a rig_map= argument: None, a dict {user joint:
    model joint or None}, a path to a JSON file, or JSON text."""
    if rig_map is None:
        return None, None
    if isinstance(rig_map, dict):
        return json.dumps(rig_map), None
    if isinstance(rig_map, str) and rig_map.lstrip().startswith("{"):
        return rig_map, None
    if isinstance(rig_map, (str, os.PathLike)):
        return None, os.fspath(rig_map)
    raise TypeError("rig_map must be a dict, a JSON file's path or JSON text, not %s" % type(rig_map).__name__)


def _keywords_after(*old_order: str) -> Callable[[_F], _F]:
    """Makes the arguments after the positional ones keyword-only while still
    accepting, with a DeprecationWarning, the old call that gave them by
    position (in `old_order`)."""

    def wrap(fn: _F) -> _F:
        params = inspect.signature(fn).parameters.values()
        positional = sum(1 for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD))

        @functools.wraps(fn)
        def call(*args: Any, **kwargs: Any) -> Any:
            if len(args) > positional:
                extra = args[positional:]
                if len(extra) > len(old_order):
                    raise TypeError("%s() takes at most %d positional arguments (%d given)" %
                                    (fn.__name__, positional + len(old_order), len(args)))
                names = old_order[:len(extra)]
                for name in names:
                    if name in kwargs:
                        raise TypeError("%s() got multiple values for argument '%s'" % (fn.__name__, name))
                warnings.warn("%s(): giving %s by position is deprecated; pass %s" %
                              (fn.__name__, ", ".join(names), ", ".join(n + "=..." for n in names)),
                              DeprecationWarning, stacklevel=2)
                kwargs.update(zip(names, extra))
                args = args[:positional]
            return fn(*args, **kwargs)

        return call  # type: ignore[return-value]

    return wrap


# ------------------------------------------------------------------ library-wide


def version() -> str:
    """The library's version.

    Returns
    -------
    str
        MF_VERSION_STRING of the loaded libmotionfield.so, e.g. "0.1.0" (the
        project's version in CMakeLists.txt; ``__version__`` is the same).

    Raises
    ------
    None
    """
    return _c.mf_version_string().decode()


#: The package's version: the loaded library's (one source of truth, CMakeLists.txt's project(VERSION)).
__version__: str = version()


def abi_version() -> int:
    """The loaded library's ABI version (the SONAME's number).

    Returns
    -------
    int
        MF_ABI_VERSION of the library (this package needs 0).

    Raises
    ------
    None
    """
    return int(_c.mf_abi_version())


def library_path() -> str:
    """Path of the loaded libmotionfield.so.

    Found through ``$MOTIONFIELD_LIBRARY``, then ``motionfield/lib/`` inside
    this package (a bundled copy), then the CMake install tree, then the
    source checkout's ``build*/capi``, then the system's library path.

    Returns
    -------
    str
        The path the library was loaded from.

    Raises
    ------
    None
    """
    return _c.library_path


def set_num_threads(n: int) -> None:
    """Sets the intra-op threads of the numeric work, for the whole process.

    Parameters
    ----------
    n : int
        Number of threads, 1..1024. Until it is called, each task runs on one
        thread (its calling thread), as the CLI's default. More than one pays only
        on an otherwise idle machine: libtorch's OpenMP threads spin while they
        wait, and with another process busy a solve on two threads of two cores
        took 25-40x as long as on one.

    Returns
    -------
    None

    Raises
    ------
    InvalidArgumentError
        If `n` is out of range.
    """
    _check(_c.mf_set_num_threads(_int_arg(n, "n")))


def get_num_threads() -> int:
    """The intra-op threads of the numeric work.

    Returns
    -------
    int
        The threads a task started now on the calling thread runs with: the
        count set by set_num_threads(), else 1.

    Raises
    ------
    Error
        Never in practice.
    """
    n = ctypes.c_int32(0)
    _check(_c.mf_get_num_threads(ctypes.byref(n)))
    return n.value


class Method(NamedTuple):
    """A registered method (see methods()).

    Attributes
    ----------
    name : str
        What to pass as ``method=``.
    description : str
        One line about it.
    needs_model : bool
        It runs only with a Model.
    completes : bool
        It does in-betweening and gap filling.
    resamples : bool
        It does resampling.
    """

    name: str
    description: str
    needs_model: bool
    completes: bool
    resamples: bool


def methods() -> List[Method]:
    """Every registered method.

    Returns
    -------
    list of Method
        In the library's order ("interp", "zerovel", the prior's, ...).

    Raises
    ------
    Error
        Never in practice.
    """
    count = ctypes.c_int32(0)
    _check(_c.mf_method_count(ctypes.byref(count)))
    out = []
    for i in range(count.value):
        name, description, flags = ctypes.c_char_p(), ctypes.c_char_p(), ctypes.c_uint32()
        _check(_c.mf_method_get(i, ctypes.byref(name), ctypes.byref(description), ctypes.byref(flags)))
        f = flags.value
        out.append(Method(name.value.decode(), description.value.decode(), bool(f & _c.METHOD_NEEDS_MODEL),
                          bool(f & _c.METHOD_COMPLETES), bool(f & _c.METHOD_RESAMPLES)))
    return out


def find_method(name: str) -> Method:
    """The method called `name` (mf_method_find), or the library's error.

    The check the CLI makes of a job's method before reading anything
    (``motionfield batch`` and ``python3 -m motionfield.dask``).

    Parameters
    ----------
    name : str
        A method name, e.g. "interp" or "nemf".

    Returns
    -------
    Method
        Its name, description and flags.

    Raises
    ------
    InvalidArgumentError
        If no method has that name (the library's message lists the names).
    """
    index = ctypes.c_int32(0)
    _check(_c.mf_method_find(name.encode(), ctypes.byref(index)))
    return methods()[index.value]


def printable_text(text: Union[str, bytes]) -> str:
    """`text` as the library prints messages (mf_printable_text).

    Control bytes and terminal escape sequences are escaped and the text is cut
    at MF_MESSAGE_MAX_BYTES: what the CLI does to every message that quotes a
    file name or input before printing it.

    Parameters
    ----------
    text : str or bytes
        The text (str is encoded as UTF-8, lone surrogates as "surrogateescape"
        bytes).

    Returns
    -------
    str
        The printable text (invalid UTF-8 left in it is decoded with U+FFFD).

    Raises
    ------
    OutOfMemoryError
        Never in practice.
    """
    data = text if isinstance(text, bytes) else text.encode("utf-8", "surrogateescape")
    needed = ctypes.c_size_t(0)
    _check(_c.mf_printable_text(data, len(data), None, 0, ctypes.byref(needed)))
    buf = ctypes.create_string_buffer(needed.value)
    _check(_c.mf_printable_text(data, len(data), buf, needed.value, ctypes.byref(needed)))
    return buf.value.decode("utf-8", "replace")


@functools.lru_cache(maxsize=None)
def _methods_by_name() -> Dict[str, Method]:
    return {m.name: m for m in methods()}


def default_model_path() -> Optional[str]:
    """Path of the default model (the CLI's, mf_model_default_path).

    ``$MF_MODEL`` if set; else ``share/motionfield/motionfield-prior.mfm``
    installed next to the library (``<prefix>/share/motionfield`` of a CMake
    install, ``motionfield/share/motionfield`` of a package that bundles the
    library); else the source tree's ``models/motionfield-prior.mfm``.

    Returns
    -------
    str or None
        The path, or None when there is no default model.

    Raises
    ------
    Error
        Never in practice.
    """
    path = _read_string(_c.mf_model_default_path)
    return path or None


_default_models: Dict[str, "Model"] = {}
_default_models_lock = threading.Lock()


def default_model() -> Optional["Model"]:
    """The default model, loaded on first use and then shared.

    What the tasks use without ``model=`` (and what the CLI uses without
    ``--model``): the file at default_model_path() with the transformer
    in-betweeners and the rig anatomy found next to it.

    Returns
    -------
    Model or None
        The shared Model, or None when there is no default model.

    Raises
    ------
    FileError, ModelError
        If the default model exists but cannot be loaded (the message names it).
    """
    path = default_model_path()
    if path is None:
        return None
    with _default_models_lock:
        model = _default_models.get(path)
        if model is None:
            try:
                model = Model(path)
            except Error as e:
                raise type(e)("cannot load the default model: %s" % e, e.status) from None
            _default_models[path] = model
    return model


@_keywords_after("model")
def default_method(*, model: Optional["Model"] = None) -> str:
    """The in-betweening and gap-filling method used when none is named.

    The best measured method that can run with the model (mf_default_method):
    "nemf-detail" when it has the two-stage transformer, "nemf" with the
    prior alone, "interp" without a model. Resampling without a method uses
    "prior" with a model and "cubic" without; re-navigation uses "nemf".
    solve() with a trajectory uses "nemf-refine" instead when the model has the
    keyframe transformer (Solution.method says which ran).

    Parameters
    ----------
    model : Model, optional
        The model; by default the default model (see default_model()), as the
        tasks and the CLI use it.

    Returns
    -------
    str
        The method's name.

    Raises
    ------
    FileError, ModelError
        If the default model exists but cannot be loaded.
    """
    if model is None:
        model = default_model()
    name = ctypes.c_char_p()
    _check(_c.mf_default_method(model._live() if model is not None else None, ctypes.byref(name)))
    return name.value.decode()


# ------------------------------------------------------------------ handles


_H = TypeVar("_H", bound="_Handle")


class _Handle:
    _destroy: Any = None
    _handle: Any

    def __init__(self, handle: Any) -> None:
        self._handle = handle

    def close(self) -> None:
        """Frees the C object now (otherwise when garbage-collected).

        Returns
        -------
        None

        Raises
        ------
        None
        """
        if getattr(self, "_handle", None):
            type(self)._destroy(self._handle)
            self._handle = None

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self) -> Any:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    @classmethod
    def _wrap(cls: Type[_H], handle: Any) -> _H:
        # An object around a handle the C API made, without the public constructor.
        self = cls.__new__(cls)
        _Handle.__init__(self, handle)
        return self

    def _live(self) -> Any:
        if not self._handle:
            raise InvalidArgumentError("%s is closed" % type(self).__name__)
        return self._handle

    def _i32(self, getter: Any) -> int:
        v = ctypes.c_int32(0)
        _check(getter(self._live(), ctypes.byref(v)))
        return v.value

    def _f64(self, getter: Any) -> float:
        v = ctypes.c_double(0)
        _check(getter(self._live(), ctypes.byref(v)))
        return v.value


class _Skeletal(_Handle):
    # The skeleton accessors of Model and Motion: the subclass names its C getters.
    _get_joint_count: Any = None
    _get_joint_name: Any = None
    _get_parents: Any = None
    _get_offsets: Any = None

    @property
    def joint_count(self) -> int:
        """Number of joints of the skeleton."""
        return self._i32(type(self)._get_joint_count)

    @property
    def joint_names(self) -> List[str]:
        """Joint names of the skeleton."""
        return [_read_string(type(self)._get_joint_name, self._live(), j) for j in range(self.joint_count)]

    @property
    def parents(self) -> npt.NDArray[np.int32]:
        """[joints] int32 parent indices, -1 for the root."""
        n = self.joint_count
        out = (ctypes.c_int32 * n)()
        _check(type(self)._get_parents(self._live(), out, n, None))
        return np.array(out, dtype=np.int32)

    @property
    def offsets(self) -> FloatArray:
        """[joints, 3] float32 bone offsets, metres."""
        return _read_floats(type(self)._get_offsets, self._live(), (-1, 3))


class Model(_Skeletal):
    """A loaded prior. Immutable; share one between threads.

    Parameters
    ----------
    path : str or os.PathLike, optional
        A model file (.mfm); None loads the default model file (see
        default_model_path(); default_model() shares one instead). The
        transformer in-betweeners (motionfield-twostage.mfm,
        motionfield-citl.mfm) and the rig anatomy (motionfield-rig.json) next
        to it are loaded too.

    Raises
    ------
    FileError
        If the file cannot be read, or `path` is None and there is no default model.
    ModelError
        If it is not a valid model file.

    Attributes
    ----------
    joint_count : int
    joint_names : list of str
    parents : numpy.ndarray
        [joints] int32, -1 for the root.
    offsets : numpy.ndarray
        [joints, 3] float32, metres.
    fps : float
        The frame rate the model works at.
    window : int
        Frames per window.
    latent_sizes : tuple of int
        (local_size, global_size).
    """

    _destroy = staticmethod(_c.mf_model_destroy)
    _get_joint_count = staticmethod(_c.mf_model_get_joint_count)
    _get_joint_name = staticmethod(_c.mf_model_get_joint_name)
    _get_parents = staticmethod(_c.mf_model_get_parents)
    _get_offsets = staticmethod(_c.mf_model_get_offsets)

    def __init__(self, path: Optional[PathLike] = None) -> None:
        handle = ctypes.POINTER(_c.MfModel)()
        _check(_c.mf_model_load(None if path is None else os.fspath(path).encode(), ctypes.byref(handle)))
        super().__init__(handle)

    @classmethod
    def from_bytes(cls, data: bytes) -> "Model":
        """A model from the bytes of a model file.

        No transformer and no rig anatomy are loaded with it: it serves only
        motions on the model's own skeleton (see with_inbetweener()).

        Parameters
        ----------
        data : bytes-like
            The file's contents (copied).

        Returns
        -------
        Model

        Raises
        ------
        ModelError
            If it is not a valid model file.
        """
        data = bytes(data)
        handle = ctypes.POINTER(_c.MfModel)()
        _check(_c.mf_model_load_from_memory(data, len(data), ctypes.byref(handle)))
        return cls._wrap(handle)

    def with_inbetweener(self, path: PathLike) -> "Model":
        """This model plus a transformer in-betweener file.

        Model(path) already loads motionfield-twostage.mfm and
        motionfield-citl.mfm found next to the prior's file.

        Parameters
        ----------
        path : str or os.PathLike
            A transformer file of kind "twostage" or "citl" (read from the file).

        Returns
        -------
        Model
            A new Model: this one's prior and transformers plus that one.

        Raises
        ------
        FileError
            If the file cannot be read.
        ModelError
            If it is not a transformer file or does not fit the prior.
        """
        handle = ctypes.POINTER(_c.MfModel)()
        _check(_c.mf_model_with_inbetweener(self._live(), os.fspath(path).encode(), ctypes.byref(handle)))
        return type(self)._wrap(handle)

    def has_inbetweener(self, kind: str) -> bool:
        """Whether a transformer in-betweener is loaded.

        Parameters
        ----------
        kind : str
            "twostage" (methods context, detail, nemf-context, nemf-detail) or
            "citl" (citl, nemf-citl).

        Returns
        -------
        bool

        Raises
        ------
        InvalidArgumentError
            If `kind` is neither.
        """
        v = ctypes.c_int32(0)
        _check(_c.mf_model_has_inbetweener(self._live(), str(kind).encode(), ctypes.byref(v)))
        return v.value != 0

    @property
    def fps(self) -> float:
        """The frame rate the model works at."""
        return self._f64(_c.mf_model_get_fps)

    @property
    def window(self) -> int:
        """Frames per window."""
        return self._i32(_c.mf_model_get_window)

    def describe(self) -> Dict[str, Any]:
        """What the model holds and what did not load with it (mf_model_describe).

        Returns
        -------
        dict
            {"format_version", "joints", "fps", "window", "inbetweeners":
            {kind: {"file", "loaded", "error"}}, "rig_anatomy",
            "rig_anatomy_error"}: a transformer file next to the model that
            was there but did not load has "loaded" False and the reason in
            "error" (the default method then runs without it).

        Raises
        ------
        InvalidArgumentError
            If the model is closed.
        """
        return json.loads(_read_string(_c.mf_model_describe, self._live()))

    @property
    def latent_sizes(self) -> Tuple[int, int]:
        """(local_size, global_size)."""
        zl, zg = ctypes.c_int32(0), ctypes.c_int32(0)
        _check(_c.mf_model_get_latent_sizes(self._live(), ctypes.byref(zl), ctypes.byref(zg)))
        return zl.value, zg.value


class Motion(_Skeletal):
    """A skeleton with per-frame local rotations and root positions. Immutable.

    Made by Motion.from_arrays(), Motion.load_bvh(), Motion.from_bvh_text()
    and the tasks.

    Raises
    ------
    TypeError
        When called directly: Motion() makes nothing.

    Attributes
    ----------
    frame_count, joint_count : int
    fps : float
    frame_time : float
        Seconds between frames as a BVH file of this motion says them.
    length_scale : float
        Metres per file unit the motion was read with.
    joint_names : list of str
    parents : numpy.ndarray
        [joints] int32.
    offsets : numpy.ndarray
        [joints, 3] float32, metres.
    rotations : numpy.ndarray
        [frames, joints, 4] float32 local rotations (w, x, y, z).
    root_positions : numpy.ndarray
        [frames, 3] float32, metres.
    global_positions : numpy.ndarray
        [frames, joints, 3] float32, metres.
    warnings : str
        What the task that made this motion wants the caller to know.
    """

    _destroy = staticmethod(_c.mf_motion_destroy)
    _get_joint_count = staticmethod(_c.mf_motion_get_joint_count)
    _get_joint_name = staticmethod(_c.mf_motion_get_joint_name)
    _get_parents = staticmethod(_c.mf_motion_get_parents)
    _get_offsets = staticmethod(_c.mf_motion_get_offsets)

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        raise TypeError("use Motion.from_arrays, Motion.load_bvh or Motion.from_bvh_text")

    @classmethod
    @_keywords_after("joint_names", "parents", "offsets", "model", "like")
    def from_arrays(cls, rotations: npt.ArrayLike, root_positions: npt.ArrayLike, fps: float, *,
                    joint_names: Optional[Sequence[str]] = None, parents: Optional[Sequence[int]] = None,
                    offsets: Optional[npt.ArrayLike] = None, model: Optional[Model] = None,
                    like: Optional["Motion"] = None) -> "Motion":
        """A motion from arrays, on a skeleton given one of three ways.

        Parameters
        ----------
        rotations : array_like
            [frames, joints, 4] local rotations (w, x, y, z), unit quaternions.
        root_positions : array_like
            [frames, 3] root positions, metres.
        fps : float
            Frame rate.
        joint_names : sequence of str, optional
            The skeleton's joint names (with `parents` and `offsets`).
        parents : sequence of int, optional
            Parent index of each joint, -1 for the root.
        offsets : array_like, optional
            [joints, 3] bone offsets, metres.
        model : Model, optional
            Use the model's skeleton instead.
        like : Motion, optional
            Use another motion's skeleton (and BVH layout) instead.

        Returns
        -------
        Motion

        Raises
        ------
        InvalidArgumentError
            If the shapes disagree, a quaternion is not finite and non-zero, or
            not exactly one skeleton is given.
        """
        rot = np.ascontiguousarray(rotations, dtype=np.float32)
        if rot.ndim != 3 or rot.shape[2] != 4:
            raise InvalidArgumentError("rotations must have shape [frames, joints, 4], not %s" % list(rot.shape))
        frames, joints = rot.shape[0], rot.shape[1]
        root = _float_array(root_positions, (3,), "root_positions")
        if root.shape[0] != frames:
            raise InvalidArgumentError("root_positions has %d frames, rotations %d" % (root.shape[0], frames))
        out = ctypes.POINTER(_c.MfMotion)()
        given = [x is not None for x in (joint_names, model, like)]
        if sum(given) != 1:
            raise InvalidArgumentError("give exactly one skeleton: joint_names (with parents and offsets), model or like")
        if model is not None:
            _check(_c.mf_motion_create_for_model(model._live(), joints, frames, float(fps), _f32_ptr(rot),
                                                 _f32_ptr(root), ctypes.byref(out)))
        elif like is not None:
            _check(_c.mf_motion_create_like(like._live(), joints, frames, float(fps), _f32_ptr(rot), _f32_ptr(root),
                                            ctypes.byref(out)))
        else:
            assert joint_names is not None
            if parents is None or offsets is None:
                raise InvalidArgumentError("joint_names needs parents and offsets")
            if len(joint_names) != joints or len(parents) != joints:
                raise InvalidArgumentError("joint_names and parents must have one entry per joint (%d)" % joints)
            names = (ctypes.c_char_p * joints)(*[str(n).encode() for n in joint_names])
            par = (ctypes.c_int32 * joints)(*_int_list(parents, "parents").tolist())
            off = _float_array(offsets, (3,), "offsets")
            if off.shape[0] != joints:
                raise InvalidArgumentError("offsets must have shape [%d, 3], not %s" % (joints, list(off.shape)))
            _check(_c.mf_motion_create(joints, names, par, _f32_ptr(off), frames, float(fps), _f32_ptr(rot),
                                       _f32_ptr(root), ctypes.byref(out)))
        return cls._wrap(out)

    @classmethod
    def load_bvh(cls, path: PathLike, units: Union[str, float, None] = None,
                 length_scale: Optional[float] = None) -> "Motion":
        """Reads a BVH file.

        Parameters
        ----------
        path : str or os.PathLike
            The file.
        units : str or float, optional
            None or "auto" (detected from the leg length; centimetres when no
            legs are found), "cm", "m", "mm", "in", "ft", "asf", or metres per
            file unit. The motion remembers it (length_scale) and writes in it.
        length_scale : float, optional
            Metres per file unit (the same as a number for `units`).

        Returns
        -------
        Motion

        Raises
        ------
        FileError
            If the file cannot be read.
        InvalidArgumentError
            If it is not valid BVH (the message says where), or the unit is unknown.
        """
        out = ctypes.POINTER(_c.MfMotion)()
        o = _bvh_options(_units_scale(units, length_scale))
        _check(_c.mf_motion_load_bvh(os.fspath(path).encode(), ctypes.byref(o), ctypes.byref(out)))
        return cls._wrap(out)

    @classmethod
    def from_bvh_text(cls, text: Union[str, bytes], units: Union[str, float, None] = None,
                      length_scale: Optional[float] = None) -> "Motion":
        """Reads BVH from a string.

        Parameters
        ----------
        text : str or bytes
            The BVH text.
        units, length_scale
            As in load_bvh().

        Returns
        -------
        Motion

        Raises
        ------
        InvalidArgumentError
            If it is not valid BVH ("<memory>:LINE: ..."), or the unit is unknown.
        """
        data = text.encode() if isinstance(text, str) else bytes(text)
        out = ctypes.POINTER(_c.MfMotion)()
        o = _bvh_options(_units_scale(units, length_scale))
        _check(_c.mf_motion_load_bvh_from_memory(data, len(data), ctypes.byref(o), ctypes.byref(out)))
        return cls._wrap(out)

    def save_bvh(self, path: PathLike, length_scale: Optional[float] = None) -> None:
        """Writes BVH (atomically), keeping the layout of the BVH it came from.

        Parameters
        ----------
        path : str or os.PathLike
            The file.
        length_scale : float, optional
            Metres per file unit to write in; by default the motion's.

        Returns
        -------
        None

        Raises
        ------
        FileError
            If the file cannot be written.
        """
        o = _bvh_options(length_scale)
        _check(_c.mf_motion_save_bvh(self._live(), os.fspath(path).encode(), ctypes.byref(o)))

    def to_bvh_text(self, length_scale: Optional[float] = None) -> str:
        """The BVH text save_bvh() would write.

        Parameters
        ----------
        length_scale : float, optional
            Metres per file unit to write in; by default the motion's.

        Returns
        -------
        str

        Raises
        ------
        InvalidArgumentError
            If `length_scale` is not positive.
        """
        o = _bvh_options(length_scale)
        return _read_string(_c.mf_motion_save_bvh_to_memory, self._live(), ctypes.byref(o))

    def save_gltf(self, path: PathLike, format: Optional[str] = None) -> None:
        """Writes glTF 2.0 (atomically): a skin-less armature and one animation.

        One node per joint (named after it, its rest offset as translation, the
        skeleton's hierarchy) and one animation with every joint's rotation and
        the root's translation at the frame times; metres (a BVH's unit
        converted with the length scale it was read with), seconds, Y up
        (mf_motion_save_gltf).

        Parameters
        ----------
        path : str or os.PathLike
            The file.
        format : {None, "auto", "glb", "gltf"}, optional
            "glb" binary, "gltf" JSON with the buffer embedded (base64); None or
            "auto" from the extension of `path` (.glb or .gltf).

        Returns
        -------
        None

        Raises
        ------
        InvalidArgumentError
            If the format is unknown, or None with another extension.
        FileError
            If the file cannot be written.
        """
        o = _gltf_options(format)
        _check(_c.mf_motion_save_gltf(self._live(), os.fspath(path).encode(), ctypes.byref(o)))

    def to_gltf_bytes(self, format: str = "glb") -> bytes:
        """The bytes save_gltf() would write.

        Parameters
        ----------
        format : {"glb", "gltf"}, optional
            Binary glTF (the default) or the JSON text with the buffer embedded.

        Returns
        -------
        bytes

        Raises
        ------
        InvalidArgumentError
            If the format is unknown.
        """
        o = _gltf_options(format)
        needed = ctypes.c_size_t(0)
        _check(_c.mf_motion_save_gltf_to_memory(self._live(), ctypes.byref(o), None, 0, ctypes.byref(needed)))
        buf = (ctypes.c_uint8 * needed.value)()
        _check(_c.mf_motion_save_gltf_to_memory(self._live(), ctypes.byref(o), buf, needed.value,
                                                ctypes.byref(needed)))
        return bytes(buf)

    @property
    def frame_count(self) -> int:
        """Number of frames."""
        return self._i32(_c.mf_motion_get_frame_count)

    @property
    def fps(self) -> float:
        """Frame rate."""
        return self._f64(_c.mf_motion_get_fps)

    @property
    def length_scale(self) -> float:
        """Metres per file unit the motion was read with (given or detected);
        0.01 for motions from arrays. Task results keep their input's."""
        return self._f64(_c.mf_motion_get_length_scale)

    @property
    def warnings(self) -> str:
        """What the task that made this motion wants the caller to know although
        it succeeded (e.g. a resampling whose frame count was rounded down), one
        sentence per line; "" if nothing."""
        return _read_string(_c.mf_motion_get_warnings, self._live())

    @property
    def frame_time(self) -> float:
        """Seconds between frames as a BVH file of this motion says them."""
        return self._f64(_c.mf_motion_get_frame_time)

    @property
    def rotations(self) -> FloatArray:
        """[frames, joints, 4] float32 local rotations (w, x, y, z)."""
        return _read_floats(_c.mf_motion_get_rotations, self._live(), (self.frame_count, self.joint_count, 4))

    @property
    def root_positions(self) -> FloatArray:
        """[frames, 3] float32 root positions, metres."""
        return _read_floats(_c.mf_motion_get_root_positions, self._live(), (-1, 3))

    @property
    def global_positions(self) -> FloatArray:
        """[frames, joints, 3] float32 joint positions (forward kinematics), metres."""
        return _read_floats(_c.mf_motion_get_global_positions, self._live(),
                            (self.frame_count, self.joint_count, 3))

    def __repr__(self) -> str:
        if not self._handle:
            return "<motionfield.Motion (closed)>"
        return "<motionfield.Motion %d frames at %g fps, %d joints>" % (self.frame_count, self.fps, self.joint_count)


class CancelToken(_Handle):
    """Stops a running task from any thread: ``token.cancel()``.

    Pass it as ``cancel=`` to a task; the task then raises CancelledError.

    Raises
    ------
    OutOfMemoryError
        If it cannot be made.

    Attributes
    ----------
    cancelled : bool
        Whether cancel() was called (and reset() not since).
    """

    _destroy = staticmethod(_c.mf_cancel_token_destroy)

    def __init__(self) -> None:
        handle = ctypes.POINTER(_c.MfCancelToken)()
        _check(_c.mf_cancel_token_create(ctypes.byref(handle)))
        super().__init__(handle)

    def cancel(self) -> None:
        """Cancels the tasks running with this token, and those started with it later.

        Returns
        -------
        None

        Raises
        ------
        InvalidArgumentError
            If the token is closed.
        """
        _check(_c.mf_cancel_token_cancel(self._live()))

    def reset(self) -> None:
        """Makes the token usable again after cancel().

        Returns
        -------
        None

        Raises
        ------
        InvalidArgumentError
            If the token is closed.
        """
        _check(_c.mf_cancel_token_reset(self._live()))

    @property
    def cancelled(self) -> bool:
        """Whether cancel() was called (and reset() not since)."""
        v = ctypes.c_int32(0)
        _check(_c.mf_cancel_token_is_cancelled(self._live(), ctypes.byref(v)))
        return bool(v.value)


class OutputSet(_Handle):
    """The files one job reads and writes (mf_output_set): the one safe
    writer of the C API, for several outputs at once.

    Files are checked as they are added: no two outputs, and no output and
    input, may be the same file (by inode, through links; devices excepted).
    ``write()`` stages an output (a temporary file with a unique name beside
    it; a device's bytes are kept and written in place), ``commit()`` puts
    them all in place; closed or collected without ``commit()``, the set
    leaves none of them behind.

    Raises
    ------
    OutOfMemoryError
        If the set cannot be made.
    """

    _destroy = staticmethod(_c.mf_output_set_destroy)

    def __init__(self) -> None:
        handle = ctypes.POINTER(_c.MfOutputSet)()
        _check(_c.mf_output_set_create(ctypes.byref(handle)))
        super().__init__(handle)

    def add_input(self, path: PathLike, role: str = "input") -> None:
        """Adds a file the job reads.

        Parameters
        ----------
        path : str or os.PathLike
            The file as the user named it ("" adds nothing).
        role : str
            What it is, for messages ("input", "rig map file").

        Returns
        -------
        None

        Raises
        ------
        InvalidArgumentError
            If it is an output added before ("the output O is the input I:
            refusing to overwrite it (name another output file)").
        """
        _check(_c.mf_output_set_add_input(self._live(), os.fsencode(path), _str_arg(role, "role").encode()))

    def add_output(self, path: PathLike, role: str = "output") -> None:
        """Adds a file the job writes.

        Parameters
        ----------
        path : str or os.PathLike
            The file as the user named it.
        role : str
            What it is, for messages ("output", "alternative", "report").

        Returns
        -------
        None

        Raises
        ------
        FileError
            If it is a directory or its directory does not exist.
        InvalidArgumentError
            If it is an input or another output (nothing is added).
        """
        _check(_c.mf_output_set_add_output(self._live(), os.fsencode(path), _str_arg(role, "role").encode()))

    def merge(self, job: "OutputSet", label: str) -> None:
        """Adds every file of another job's set, or none (a batch's check).

        Parameters
        ----------
        job : OutputSet
            The job's files.
        label : str
            The job's name in later messages ("line 3").

        Returns
        -------
        None

        Raises
        ------
        InvalidArgumentError
            If one of its files is one of this set's and either is written
            ("line 2 already writes O: ...").
        """
        _instance_arg(job, OutputSet, "job")
        _check(_c.mf_output_set_merge(self._live(), job._live(), _str_arg(label, "label").encode()))

    def write(self, path: PathLike, data: Union[bytes, str]) -> None:
        """Stages the bytes of an output.

        Parameters
        ----------
        path : str or os.PathLike
            The output, named as it was added.
        data : bytes or str
            Its bytes (a str is written as UTF-8).

        Returns
        -------
        None

        Raises
        ------
        FileError
            If the temporary file cannot be written ("cannot write F: No
            space left on device").
        InvalidArgumentError
            If `path` is no output of the set.
        """
        raw = data.encode() if isinstance(data, str) else bytes(data)
        _check(_c.mf_output_set_write(self._live(), os.fsencode(path), raw, len(raw)))

    def write_motion(self, path: PathLike, motion: "Motion") -> None:
        """Stages a motion: glTF 2.0 for a .glb or .gltf name, BVH otherwise.

        Parameters
        ----------
        path : str or os.PathLike
            The output, named as it was added.
        motion : Motion
            The motion.

        Returns
        -------
        None

        Raises
        ------
        FileError
            As write().
        """
        ext = os.path.splitext(os.fspath(path))[1].lower()
        _instance_arg(motion, Motion, "motion")
        self.write(path, motion.to_gltf_bytes(ext[1:]) if ext in (".glb", ".gltf") else motion.to_bvh_text())

    def commit(self) -> None:
        """Puts every staged output in place (devices written in place, files renamed), once.

        Returns
        -------
        None

        Raises
        ------
        FileError
            With the file and the reason; the outputs not yet in place are removed.
        """
        _check(_c.mf_output_set_commit(self._live()))


class Progress(NamedTuple):
    """What a progress callback is given.

    Attributes
    ----------
    iteration : int
        Iterations done.
    max_iterations : int
        The most there will be.
    energy : float
        The solver's current energy (0 for methods without one).
    """

    iteration: int
    max_iterations: int
    energy: float


# ------------------------------------------------------------------ tasks


class _TaskCall:
    """The options struct of one task call, and its progress callback (kept
    alive for the call; exceptions it raises cancel the task and are re-raised)."""

    def __init__(self, method: Optional[str], seed: int, progress: Optional[ProgressCallback],
                 cancel: Optional[CancelToken], rig_map: Optional[RigMap] = None, max_iterations: int = 0) -> None:
        method = _str_arg(method, "method", optional=True)
        seed = _int_arg(seed, "seed", 0, 2**64 - 1)
        max_iterations = _int_arg(max_iterations, "max_iterations", 0, 100000)
        if progress is not None and not callable(progress):
            raise TypeError("progress must be callable, not %s" % type(progress).__name__)
        _instance_arg(cancel, CancelToken, "cancel", optional=True)
        self.options = _c.MfTaskOptions()
        _check(_c.mf_task_options_init(ctypes.byref(self.options)))
        self._method = method.encode() if method else None
        self.options.method = self._method
        text, path = _rig_map_args(rig_map)
        self._rig_map = (text.encode() if text else None, path.encode() if path else None)
        self.options.rig_map, self.options.rig_map_path = self._rig_map
        self.options.seed = seed
        self.options.max_iterations = max_iterations
        self.error: Optional[BaseException] = None
        if progress is not None:
            def trampoline(_user_data: Any, p: Any) -> int:
                try:
                    return 1 if progress(Progress(p.contents.iteration, p.contents.max_iterations,
                                                  p.contents.energy)) else 0
                except BaseException as e:  # noqa: B902 (re-raised after the call)
                    self.error = e
                    return 1
            self._callback = _c.PROGRESS_FN(trampoline)
            self.options.progress = self._callback
        if cancel is not None:
            self.options.cancel = cancel._live()

    def run(self, fn: Any, *args: Any, out_type: Any = None) -> Any:
        out = ctypes.POINTER(out_type or _c.MfMotion)()
        status = fn(*args, ctypes.byref(self.options), ctypes.byref(out))
        if self.error is not None:
            raise self.error
        _check(status)
        return out if out_type is not None else Motion._wrap(out)


def _task_model(model: Optional[Model], method: Optional[str]) -> Any:
    """The model handle a task runs with, chosen as the CLI chooses it: the
    given model; else the default model when no method is named or the method
    needs a model (None when there is none: the default method is then one
    without a model); else none."""
    _instance_arg(model, Model, "model", optional=True)
    _str_arg(method, "method", optional=True)
    if model is None and (not method or _needs_model(method)):
        model = default_model()
    return model._live() if model is not None else None


def _needs_model(method: str) -> bool:
    m = _methods_by_name().get(method)
    return m is not None and m.needs_model  # unknown names: the library says so


def _required_model(model: Optional[Model], what: str) -> Model:
    if model is None:
        model = default_model()
        if model is None:
            raise ModelError("%s needs the model, and there is no default model (pass model=, or set MF_MODEL)" % what,
                             _c.ERROR_MODEL)
    return model


_TASK_OPTIONS = ("method", "model", "seed", "progress", "cancel", "rig_map")

_TASK_PARAMETERS_DOC = """\
    method : str, optional
        A method name (see methods()); by default the CLI's default, the best
        one that can run with the model (see default_method()).
    model : Model, optional
        By default the default model (see default_model()), loaded when no
        method is named or the method needs one, as the CLI does without
        ``--model``.
    seed : int, optional
        Seed of the method's random choices; equal seeds give equal results.
    progress : callable, optional
        Called now and then with a Progress; returning True cancels the task.
        An exception it raises cancels the task and is re-raised.
    cancel : CancelToken, optional
        Cancels the task from another thread.
    rig_map : dict, str or os.PathLike, optional
        For a motion on another rig than the model's: a dict {user joint:
        model joint or None}, a JSON file's path or JSON text overriding the
        automatic map (see describe_rig()).
    max_iterations : int, optional
        Iteration budget of the methods that iterate (the "nemf*" solvers,
        "prior" resampling, re-navigation): the most iterations of the full
        solve per window; 0 (the default) = each method's own."""

_TASK_RAISES_DOC = """\
    InvalidArgumentError
        If an argument is out of range or the method is unknown (the message says which).
    ModelError
        If the method needs a model and there is none, or the model lacks a
        transformer the method needs (the message names the file).
    CancelledError
        If the progress callback or the cancel token cancelled the task.
    FileError
        If the rig map file cannot be read."""


def _task_doc(fn: _F) -> _F:
    fn.__doc__ = (fn.__doc__ or "").replace("    {task_parameters}", _TASK_PARAMETERS_DOC).replace(
        "    {task_raises}", _TASK_RAISES_DOC)
    return fn


@_task_doc
@_keywords_after(*_TASK_OPTIONS)
def inbetween(motion: Motion, keyframes: Sequence[int], *, method: Optional[str] = None,
              model: Optional[Model] = None, seed: int = 0, progress: Optional[ProgressCallback] = None,
              cancel: Optional[CancelToken] = None, rig_map: Optional[RigMap] = None,
              max_iterations: int = 0) -> Motion:
    """Keyframe in-betweening: the keyframes are kept, every other frame is produced.

    ``inbetween(motion, keys)`` gives what ``motionfield inbetween --in ...
    --keyframes ...`` gives (same default model, same default method).

    Parameters
    ----------
    motion : Motion
        The input (its non-key frames are never read).
    keyframes : sequence of int
        0-based frame indices, strictly increasing, at least two.
    {task_parameters}

    Returns
    -------
    Motion
        On the input's skeleton and BVH layout, with its length and frame rate.

    Raises
    ------
    {task_raises}
    """
    _instance_arg(motion, Motion, "motion")
    keys = _int_list(keyframes, "keyframes")
    call = _TaskCall(method, seed, progress, cancel, rig_map, max_iterations)
    return call.run(_c.mf_inbetween, _task_model(model, method), motion._live(),
                    keys.ctypes.data_as(ctypes.POINTER(ctypes.c_int32)), keys.size)


@_task_doc
@_keywords_after(*_TASK_OPTIONS)
def fill(motion: Motion, gap_begin: int, gap_end: int, *, method: Optional[str] = None,
         model: Optional[Model] = None, seed: int = 0, progress: Optional[ProgressCallback] = None,
         cancel: Optional[CancelToken] = None, rig_map: Optional[RigMap] = None, max_iterations: int = 0) -> Motion:
    """Gap filling: frames gap_begin..gap_end-1 are produced, the others kept.

    Parameters
    ----------
    motion : Motion
        The input (the gap's frames are never read).
    gap_begin, gap_end : int
        The unknown frames, 1 <= gap_begin < gap_end <= frames - 1.
    {task_parameters}

    Returns
    -------
    Motion
        On the input's skeleton and BVH layout, with its length and frame rate.

    Raises
    ------
    {task_raises}
    """
    _instance_arg(motion, Motion, "motion")
    begin, end = _int_arg(gap_begin, "gap_begin"), _int_arg(gap_end, "gap_end")
    call = _TaskCall(method, seed, progress, cancel, rig_map, max_iterations)
    return call.run(_c.mf_fill, _task_model(model, method), motion._live(), begin, end)


@_task_doc
@_keywords_after(*_TASK_OPTIONS)
def resample(motion: Motion, fps: float, *, method: Optional[str] = None, model: Optional[Model] = None,
             seed: int = 0, progress: Optional[ProgressCallback] = None, cancel: Optional[CancelToken] = None,
             rig_map: Optional[RigMap] = None, max_iterations: int = 0) -> Motion:
    """Resampling to another frame rate, keeping the time span.

    Without a method: "prior" with a model (the default one unless given),
    "cubic" (a Catmull-Rom spline) without, as the CLI does.

    Parameters
    ----------
    motion : Motion
        The input.
    fps : float
        The output's frame rate; output frame i sits at i / fps seconds.
    {task_parameters}

    Returns
    -------
    Motion
        resample_frame_count() frames; its ``warnings`` say when the count was
        rounded down.

    Raises
    ------
    {task_raises}
    """
    _instance_arg(motion, Motion, "motion")
    fps = _float_arg(fps, "fps")
    call = _TaskCall(method, seed, progress, cancel, rig_map, max_iterations)
    return call.run(_c.mf_resample, _task_model(model, method), motion._live(), fps)


# ------------------------------------------------------------------ constraints

_ROOT_FLAGS = {None: 0, "none": 0, "position": _c.ROOT_POSITION, "rotation": _c.ROOT_ROTATION,
               "both": _c.ROOT_POSITION | _c.ROOT_ROTATION}

#: A partial key: (frame, joint names) or (frame, joint names, root), root one
#: of None/"none", "position", "rotation", "both".
PartialKey = Union[Tuple[int, Sequence[str]], Tuple[int, Sequence[str], Optional[str]]]
#: An end-effector target: (frame, joint, [x, y, z]) or (frame, joint, [x, y, z], weight).
Target = Union[Tuple[int, str, npt.ArrayLike], Tuple[int, str, npt.ArrayLike, float]]


class Constraints(_Handle):
    """Constraints beyond whole-pose keyframes (docs/CONSTRAINTS.md): partial
    keys, end-effector targets and contact pins. Joints are named as in the
    input motion, frames are its frames, positions are in its world frame and
    its own length unit. Names and frames are checked when solve() runs.

    Parameters
    ----------
    json_or_dict : str or dict, optional
        The constraints file format, as JSON text or the equivalent dict;
        empty when omitted.

    Raises
    ------
    InvalidArgumentError
        If the JSON is malformed (the message names the item).
    """

    _destroy = _c.mf_constraints_destroy

    def __init__(self, json_or_dict: Union[str, Dict[str, Any], None] = None) -> None:
        out = ctypes.POINTER(_c.MfConstraints)()
        if json_or_dict is None:
            _check(_c.mf_constraints_create(ctypes.byref(out)))
        else:
            text = (json_or_dict if isinstance(json_or_dict, str) else json.dumps(json_or_dict)).encode()
            _check(_c.mf_constraints_parse_json(text, len(text), ctypes.byref(out)))
        super().__init__(out)

    @classmethod
    def load(cls, path: PathLike) -> "Constraints":
        """Reads a constraints file.

        Parameters
        ----------
        path : str or os.PathLike
            The JSON file.

        Returns
        -------
        Constraints

        Raises
        ------
        FileError
            If it cannot be read.
        InvalidArgumentError
            If it is malformed (the message starts with the path).
        """
        out = ctypes.POINTER(_c.MfConstraints)()
        _check(_c.mf_constraints_load_json(os.fsencode(path), ctypes.byref(out)))
        return cls._wrap(out)

    def add_keys(self, frames: Sequence[int]) -> "Constraints":
        """Adds whole-pose keys.

        Parameters
        ----------
        frames : sequence of int
            Frame indices, any order.

        Returns
        -------
        Constraints
            self, for chaining.

        Raises
        ------
        InvalidArgumentError
            If a frame is negative.
        """
        f = _int_list(frames, "frames")
        _check(_c.mf_constraints_add_pose_keys(self._live(), f.ctypes.data_as(ctypes.POINTER(ctypes.c_int32)), f.size))
        return self

    def add_partial_key(self, frame: int, joints: Sequence[str] = (), root: Optional[str] = None) -> "Constraints":
        """Adds a partial key: the local rotations of some joints and/or the root.

        Parameters
        ----------
        frame : int
            The key's frame.
        joints : sequence of str
            Joints whose local rotation the input gives at that frame.
        root : {None, "none", "position", "rotation", "both"}
            What of the root the key fixes.

        Returns
        -------
        Constraints
            self, for chaining.

        Raises
        ------
        InvalidArgumentError
            If the key constrains nothing or `root` is not one of the above.
        """
        if root not in _ROOT_FLAGS:
            raise InvalidArgumentError("root must be None, 'none', 'position', 'rotation' or 'both', not %r" % (root,))
        frame = _int_arg(frame, "frame")
        if isinstance(joints, str):
            raise TypeError("joints must be a sequence of joint names, not str")
        names = [_str_arg(j, "joints item %d" % i).encode() for i, j in enumerate(joints)]  # type: ignore[union-attr]
        arr = (ctypes.c_char_p * max(1, len(names)))(*names)
        _check(_c.mf_constraints_add_partial_key(self._live(), frame, arr, len(names), _ROOT_FLAGS[root]))
        return self

    def add_target(self, frame: int, joint: str, position: npt.ArrayLike, weight: float = 1.0) -> "Constraints":
        """Adds an end-effector target.

        Parameters
        ----------
        frame : int
            The frame.
        joint : str
            The joint to place (a hand, a foot).
        position : array_like, shape (3,)
            World position, in the input's length unit.
        weight : float
            Relative weight (finite, >= 0).

        Returns
        -------
        Constraints
            self, for chaining.

        Raises
        ------
        InvalidArgumentError
            If the position or the weight is not finite (or the weight negative).
        """
        p = np.ascontiguousarray(position, dtype=np.float32).reshape(-1)
        if p.size != 3:
            raise InvalidArgumentError("position must have 3 values [x, y, z], not %d" % p.size)
        frame, weight = _int_arg(frame, "frame"), _float_arg(weight, "weight")
        _check(_c.mf_constraints_add_target(self._live(), frame, _str_arg(joint, "joint").encode(),  # type: ignore[union-attr]
                                            _f32_ptr(p), weight))
        return self

    def add_contact(self, joint: str, first: int, last: int) -> "Constraints":
        """Pins a joint in place from frame `first` to frame `last` (inclusive).

        Parameters
        ----------
        joint : str
            A foot, a hand.
        first, last : int
            The pinned frames, first < last.

        Returns
        -------
        Constraints
            self, for chaining.

        Raises
        ------
        InvalidArgumentError
            If first >= last or a frame is negative.
        """
        first, last = _int_arg(first, "first"), _int_arg(last, "last")
        _check(_c.mf_constraints_add_contact(self._live(), _str_arg(joint, "joint").encode(),  # type: ignore[union-attr]
                                             first, last))
        return self

    def add_trajectory(self, trajectory: npt.ArrayLike, rows: Optional[npt.ArrayLike] = None) -> "Constraints":
        """Adds a ground trajectory the root follows (latent solvers only).

        Parameters
        ----------
        trajectory : array [N, 5] (frame, x, z, forward_x, forward_z), or frames [N]
            One row per frame: the root's ground position (the input's unit,
            world) and facing direction (any non-zero length). With `rows`,
            the frames alone.
        rows : array [N, 4] (x, z, forward_x, forward_z), optional
            The rows when `trajectory` holds the frames.

        Returns
        -------
        Constraints
            self, for chaining.

        Raises
        ------
        InvalidArgumentError
            On a shape mismatch, a non-integer or negative frame, non-finite
            values or a zero-length facing.
        """
        if rows is None:
            t = np.asarray(trajectory, dtype=np.float64)
            if t.ndim != 2 or t.shape[1] != 5:
                raise InvalidArgumentError("trajectory must be an array [N, 5] (frame, x, z, forward_x, forward_z), "
                                           "got shape %s" % (t.shape,))
            frames_f, values = t[:, 0], t[:, 1:]
        else:
            frames_f = np.asarray(trajectory, dtype=np.float64).reshape(-1)
            values = np.asarray(rows, dtype=np.float64)
            if values.ndim != 2 or values.shape != (len(frames_f), 4):
                raise InvalidArgumentError("rows must be an array [%d, 4] (x, z, forward_x, forward_z), got shape %s"
                                           % (len(frames_f), values.shape))
        if not np.all(np.isfinite(frames_f)) or np.any(frames_f != np.floor(frames_f)) or np.any(frames_f < 0) \
                or np.any(frames_f > 2**31 - 1):
            raise InvalidArgumentError("trajectory frames must be non-negative integers")
        frames = np.ascontiguousarray(frames_f, dtype=np.int32)
        flat = np.ascontiguousarray(values, dtype=np.float32).reshape(-1)
        _check(_c.mf_constraints_add_trajectory(
            self._live(), frames.ctypes.data_as(ctypes.POINTER(ctypes.c_int32)),
            flat.ctypes.data_as(ctypes.POINTER(ctypes.c_float)), len(frames)))
        return self

    def load_trajectory(self, path: PathLike) -> "Constraints":
        """Adds the trajectory of a CSV file (header frame,x,z,forward_x,forward_z;
        docs/CONSTRAINTS.md), as ``--trajectory`` does.

        Parameters
        ----------
        path : str or os.PathLike

        Returns
        -------
        Constraints
            self, for chaining.

        Raises
        ------
        FileError
            If the file cannot be read.
        InvalidArgumentError
            "<path>:<line>: ..." on a malformed file.
        """
        _check(_c.mf_constraints_load_trajectory_csv(self._live(), os.fsencode(path)))
        return self

    def to_dict(self) -> Dict[str, Any]:
        """The constraints in the file format.

        Returns
        -------
        dict

        Raises
        ------
        InvalidArgumentError
            If the object is closed.
        """
        return json.loads(_read_string(_c.mf_constraints_to_json, self._live()))


class Solution(NamedTuple):
    """What solve() returns.

    Attributes
    ----------
    motions : list of Motion
        The method's solution first, then the alternatives.
    report : dict
        How well each solution meets the constraints (mf_solution_get_report_json:
        {"unit", "solutions": [{"index", "keys", "targets", "contacts"}], "warnings"}).
    warnings : list of str
        Constraints that could not hold exactly, with the frames involved.
    report_json : str
        The report as the library formats it (what ``--report FILE`` holds).
    method : str
        The method that ran (mf_solution_get_method): the one named, else the
        default for these constraints ("nemf-refine" with a trajectory when the
        keyframe transformer is loaded; see default_method()).
    """

    motions: List[Motion]
    report: Dict[str, Any]
    warnings: List[str]
    report_json: str
    method: str = ""

    @property
    def motion(self) -> Motion:
        """The method's solution (motions[0])."""
        return self.motions[0]


@_task_doc
def solve(motion: Motion, keyframes: Sequence[int] = (), *, partial_keys: Sequence[PartialKey] = (),
          targets: Union[Sequence[Target], Dict[str, Tuple[npt.ArrayLike, npt.ArrayLike]]] = (),
          contacts: Sequence[Tuple[str, int, int]] = (), constraints: Union[Constraints, str, Dict[str, Any], None] = None,
          trajectory: Union[npt.ArrayLike, str, "os.PathLike[str]", None] = None, alternatives: int = 0, method: Optional[str] = None, model: Optional[Model] = None, seed: int = 0,
          progress: Optional[ProgressCallback] = None, cancel: Optional[CancelToken] = None,
          rig_map: Optional[RigMap] = None, max_iterations: int = 0) -> Solution:
    """Completes a motion under any constraints, with alternative solutions.

    ``solve(motion, [0, 60], targets=[(30, "Hand_R", [20, 120, 40])])`` is
    ``motionfield inbetween --keyframes 0,60 --constraints FILE`` with that
    target in FILE.

    Parameters
    ----------
    motion : Motion
        The input; only the values the keys name are read.
    keyframes : sequence of int
        Whole-pose keys.
    partial_keys : sequence of (frame, joints) or (frame, joints, root)
        Keys of some joints' local rotations; root None, "position",
        "rotation" or "both".
    targets : sequence of (frame, joint, position[, weight]), or dict
        End-effector targets in the input's unit; or {joint: (frames [n],
        positions [n, 3])} for a joint's path over many frames.
    contacts : sequence of (joint, first, last)
        Joints pinned in place over frames first..last.
    constraints : Constraints, str or dict, optional
        More constraints: a Constraints, a constraints file's path, or the
        file format as a dict.
    trajectory : array [N, 5], (frames [N], rows [N, 4]), or a CSV path, optional
        A ground trajectory the root follows (Constraints.add_trajectory,
        Constraints.load_trajectory): frame, x, z (the input's unit),
        forward_x, forward_z. Only the latent solvers follow one; other
        methods raise InvalidArgumentError.
    alternatives : int
        More solutions (0..16) from other starts, deterministic for `seed`.
    {task_parameters}

    Returns
    -------
    Solution
        The motions (the method's first), the report and the warnings.

    Raises
    ------
    {task_raises}
    """
    _instance_arg(motion, Motion, "motion")
    alternatives = _int_arg(alternatives, "alternatives", 0, 16)
    call = _TaskCall(method, seed, progress, cancel, rig_map, max_iterations)
    if constraints is None:
        c = Constraints()
    elif isinstance(constraints, Constraints):
        c = Constraints(constraints.to_dict())
    elif isinstance(constraints, dict):
        c = Constraints(constraints)
    elif isinstance(constraints, (str, os.PathLike)):
        c = Constraints.load(constraints)
    else:
        raise TypeError("constraints must be a Constraints, a dict or a file's path, not %s" %
                        type(constraints).__name__)
    keys = _int_list(keyframes, "keyframes")
    if len(keys):
        c.add_keys(keys)
    for key in partial_keys:
        c.add_partial_key(key[0], key[1], key[2] if len(key) > 2 else None)  # type: ignore[misc]
    if isinstance(targets, dict):
        for joint, (frames, positions) in targets.items():
            f = _int_list(frames, "targets[%r] frames" % (joint,))
            p = _float_array(positions, (3,), "positions").reshape(-1, 3)
            if len(f) != len(p):
                raise InvalidArgumentError("targets[%r]: %d frames but %d positions" % (joint, len(f), len(p)))
            for frame, pos in zip(f, p):
                c.add_target(int(frame), joint, pos)
    else:
        for t in targets:
            c.add_target(t[0], t[1], t[2], t[3] if len(t) > 3 else 1.0)  # type: ignore[misc]
    for joint, first, last in contacts:
        c.add_contact(joint, first, last)
    if isinstance(trajectory, (str, os.PathLike)):
        c.load_trajectory(trajectory)
    elif isinstance(trajectory, tuple) and len(trajectory) == 2:
        c.add_trajectory(trajectory[0], trajectory[1])
    elif trajectory is not None:
        c.add_trajectory(trajectory)
    handle = call.run(_c.mf_solve, _task_model(model, method), motion._live(), c._live(), alternatives,
                      out_type=_c.MfSolution)
    try:
        n = ctypes.c_int32(0)
        _check(_c.mf_solution_get_count(handle, ctypes.byref(n)))
        motions = []
        for i in range(n.value):
            m = ctypes.POINTER(_c.MfMotion)()
            _check(_c.mf_solution_get_motion(handle, i, ctypes.byref(m)))
            motions.append(Motion._wrap(m))
        text = _read_string(_c.mf_solution_get_report_json, handle)
        name = ctypes.c_char_p()
        _check(_c.mf_solution_get_method(handle, ctypes.byref(name)))
    finally:
        _c.mf_solution_destroy(handle)
    report = json.loads(text)
    return Solution(motions, report, list(report.get("warnings", [])), text, name.value.decode())


def resample_frame_count(frames: int, fps_in: float, fps_out: float) -> Tuple[int, bool]:
    """How many frames resample() makes.

    Parameters
    ----------
    frames : int
        The input's frame count.
    fps_in, fps_out : float
        The input's and the output's frame rates.

    Returns
    -------
    (int, bool)
        (frames - 1) * fps_out / fps_in + 1, rounded down unless within 1e-5
        relative of an integer; and whether it was rounded.

    Raises
    ------
    InvalidArgumentError
        If an argument is out of range.
    """
    n, rounded = ctypes.c_int32(0), ctypes.c_int32(0)
    _check(_c.mf_resample_frame_count(_int_arg(frames, "frames"), _float_arg(fps_in, "fps_in"),
                                      _float_arg(fps_out, "fps_out"), ctypes.byref(n), ctypes.byref(rounded)))
    return n.value, bool(rounded.value)


def length_unit_scale(unit: str) -> float:
    """Metres per unit of a BVH length unit name (mf_length_unit_scale).

    Parameters
    ----------
    unit : str
        "cm", "m", "mm", "in", "ft" or "asf".

    Returns
    -------
    float
        Metres per unit, e.g. 0.01 for "cm".

    Raises
    ------
    InvalidArgumentError
        If the name is not a known unit (the message lists them).
    """
    v = ctypes.c_double(0)
    _check(_c.mf_length_unit_scale(unit.encode(), ctypes.byref(v)))
    return v.value


def load_path_csv(path: PathLike) -> FloatArray:
    """Reads a ground path for renav() from a CSV file.

    Parameters
    ----------
    path : str or os.PathLike
        One "x,z" pair per line, metres; an optional header "x,z"; blank lines
        and lines starting with # skipped.

    Returns
    -------
    numpy.ndarray
        [points, 2] float32.

    Raises
    ------
    FileError
        If the file cannot be read.
    InvalidArgumentError
        If a line is not an x,z pair (the message says which).
    """
    name = os.fspath(path).encode()
    needed = ctypes.c_size_t(0)
    _check(_c.mf_path_load_csv(name, None, 0, ctypes.byref(needed)))
    out = np.empty(needed.value, dtype=np.float32)
    _check(_c.mf_path_load_csv(name, _f32_ptr(out), out.size, ctypes.byref(needed)))
    return out.reshape(-1, 2)


@_task_doc
@_keywords_after("model", "method", "polyline", "frames", "fps", "seed", "progress", "cancel", "rig_map")
def renav(reference: Motion, path: npt.ArrayLike, *, model: Optional[Model] = None, method: Optional[str] = None,
          polyline: bool = False, frames: int = 0, fps: float = 0.0, seed: int = 0,
          progress: Optional[ProgressCallback] = None, cancel: Optional[CancelToken] = None,
          rig_map: Optional[RigMap] = None, max_iterations: int = 0) -> Motion:
    """Re-navigation: a motion in the style of `reference` whose root follows `path`.

    Always needs a model (the default one unless given). Methods: "nemf"
    (L-BFGS, the default) or "nemf-adam" (NeMF's Adam reference, slower).

    Parameters
    ----------
    reference : Motion
        The style reference, on any humanoid rig.
    path : array_like
        [points, 2] ground (x, z) positions, metres (see load_path_csv()).
        A path walked faster or slower than the reference plays the reference
        at the path's pace (at most 2x either way).
    polyline : bool, optional
        False: one point per output frame at `fps`. True: the points are the
        vertices of a polyline walked at constant speed in `frames` frames.
    frames : int, optional
        With polyline=True, the output's frame count (0: at the reference's
        mean ground speed).
    fps : float, optional
        The output's frame rate (0: the reference's).
    {task_parameters}

    Returns
    -------
    Motion
        On the reference's skeleton and BVH layout.

    Raises
    ------
    {task_raises}
    """
    _instance_arg(reference, Motion, "reference")
    frames = _int_arg(frames, "frames")
    fps = _float_arg(fps, "fps")
    xz = np.ascontiguousarray(path, dtype=np.float32)
    if xz.ndim != 2 or xz.shape[1] != 2:
        raise InvalidArgumentError("path must have shape [points, 2], not %s" % list(xz.shape))
    handle = _required_model(model, "re-navigation")._live()
    o = _c.MfRenavOptions()
    _check(_c.mf_renav_options_init(ctypes.byref(o)))
    o.path_kind = _c.PATH_POLYLINE if polyline else _c.PATH_PER_FRAME
    o.frame_count = frames
    o.fps = fps
    call = _TaskCall(method, seed, progress, cancel, rig_map, max_iterations)
    return call.run(lambda *args: _c.mf_renav(*args[:4], ctypes.byref(o), *args[4:]), handle,
                    reference._live(), _f32_ptr(xz), xz.shape[0])


@_keywords_after("model", "rig_map")
def describe_rig(motion: Motion, *, model: Optional[Model] = None, rig_map: Optional[RigMap] = None) -> Dict[str, Any]:
    """How `motion`'s rig is read and mapped onto the model's (mf_rig_describe).

    Parameters
    ----------
    motion : Motion
        A motion on any humanoid rig.
    model : Model, optional
        By default the default model.
    rig_map : dict, str or os.PathLike, optional
        As in inbetween().

    Returns
    -------
    dict
        {"unit", "length_scale", "unit_detected", "joints", "map": {user joint:
        model joint}, "how": {model joint: "name" | "shape" | "map file"},
        "unmapped_user_joints", "model_joints", "retargeting", "anatomy": "rest
        pose" | "known frames" | "model rig"} (where the user's joint frames
        come from: docs/RIGS.md).

    Raises
    ------
    InvalidArgumentError
        With the reason, when the rig cannot be mapped or the map is not valid.
    ModelError
        If no model is given and there is no default model.
    FileError
        If the rig map file cannot be read.
    """
    _instance_arg(motion, Motion, "motion")
    model = _required_model(_instance_arg(model, Model, "model", optional=True), "describe_rig()")
    text, path = _rig_map_args(rig_map)
    if path is not None:  # the library's reader of rig maps, with their limit
        text = _read_string(_c.mf_rig_map_read_file, os.fsencode(path))
    try:
        out = _read_string(_c.mf_rig_describe, model._live(), motion._live(), text.encode() if text else None)
    except InvalidArgumentError as e:
        if path is None:
            raise
        raise InvalidArgumentError("%s: %s" % (path, e), e.status) from None
    return json.loads(out)


# ------------------------------------------------------------------ encode, decode

_ROOTS = {"prior": _c.ROOT_FROM_PRIOR, "input": _c.ROOT_FROM_INPUT}


def _codec_options(hop: int = 0, root: str = "prior") -> Any:
    o = _c.MfCodecOptions()
    _check(_c.mf_codec_options_init(ctypes.byref(o)))
    o.hop = _int_arg(hop, "hop")
    if root not in _ROOTS:
        raise InvalidArgumentError("root must be 'prior' or 'input', not %r" % (root,))
    o.root_source = _ROOTS[root]
    return o


class Encoding(_Handle):
    """A motion encoded by a model as window latents (made by encode()).

    Raises
    ------
    TypeError
        When called directly: Encoding() makes nothing.

    Attributes
    ----------
    window_count : int
    duration : float
        Seconds from the first to the last frame of the encoded motion.
    window_times : numpy.ndarray
        [windows] float64 start time of each window, seconds.
    local_latents : numpy.ndarray
        [windows, local_size] float32.
    global_latents : numpy.ndarray
        [windows, global_size] float32.
    """

    _destroy = staticmethod(_c.mf_encoding_destroy)

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        raise TypeError("use motionfield.encode(motion, model=model)")

    @property
    def window_count(self) -> int:
        """Number of windows."""
        return self._i32(_c.mf_encoding_get_window_count)

    @property
    def duration(self) -> float:
        """Seconds from the first to the last frame of the encoded motion."""
        return self._f64(_c.mf_encoding_get_duration)

    @property
    def window_times(self) -> npt.NDArray[np.float64]:
        """[windows] float64 start time of each window, seconds."""
        n = self.window_count
        out = np.empty(n, dtype=np.float64)
        _check(_c.mf_encoding_get_window_times(self._live(), out.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n,
                                               None))
        return out

    @property
    def local_latents(self) -> FloatArray:
        """[windows, local_size] float32."""
        return _read_floats(_c.mf_encoding_get_local_latents, self._live(), (self.window_count, -1))

    @property
    def global_latents(self) -> FloatArray:
        """[windows, global_size] float32."""
        return _read_floats(_c.mf_encoding_get_global_latents, self._live(), (self.window_count, -1))

    def with_latents(self, local: Optional[npt.ArrayLike] = None,
                     global_: Optional[npt.ArrayLike] = None) -> "Encoding":
        """A copy with other latents.

        Parameters
        ----------
        local : array_like, optional
            Shaped like local_latents; None keeps them.
        global_ : array_like, optional
            Shaped like global_latents; None keeps them.

        Returns
        -------
        Encoding

        Raises
        ------
        InvalidArgumentError
            If a size is wrong or a value is not finite.
        """
        args: List[Any] = []
        keep = []
        for z in (local, global_):
            if z is None:
                args += [None, 0]
            else:
                a = np.ascontiguousarray(z, dtype=np.float32).reshape(-1)
                keep.append(a)
                args += [_f32_ptr(a), a.size]
        out = ctypes.POINTER(_c.MfEncoding)()
        _check(_c.mf_encoding_with_latents(self._live(), *args, ctypes.byref(out)))
        return Encoding._wrap(out)

    def decode(self, fps: float, frame_count: int = 0, root: str = "prior") -> Motion:
        """Decodes frames at times i / fps.

        Parameters
        ----------
        fps : float
            The output's frame rate.
        frame_count : int, optional
            Frames i < frame_count (0: the encoded time span).
        root : {"prior", "input"}, optional
            Root positions decoded by the prior, or the encoded motion's.

        Returns
        -------
        Motion
            On the model's skeleton.

        Raises
        ------
        InvalidArgumentError
            If an argument is out of range.
        """
        o = _codec_options(root=root)
        out = ctypes.POINTER(_c.MfMotion)()
        _check(_c.mf_decode(self._live(), _float_arg(fps, "fps"), _int_arg(frame_count, "frame_count"), ctypes.byref(o),
                            ctypes.byref(out)))
        return Motion._wrap(out)

    def decode_times(self, times: npt.ArrayLike, fps: float, root: str = "prior") -> Motion:
        """Decodes one frame per time.

        Parameters
        ----------
        times : array_like
            Seconds from the first frame, any order.
        fps : float
            The frame rate the output says it has.
        root : {"prior", "input"}, optional
            As in decode().

        Returns
        -------
        Motion
            One frame per time, on the model's skeleton.

        Raises
        ------
        InvalidArgumentError
            If a time is not finite or an argument is out of range.
        """
        t = np.ascontiguousarray(times, dtype=np.float64).reshape(-1)
        o = _codec_options(root=root)
        out = ctypes.POINTER(_c.MfMotion)()
        _check(_c.mf_decode_times(self._live(), t.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), t.size,
                                  float(fps), ctypes.byref(o), ctypes.byref(out)))
        return Motion._wrap(out)


def encode(motion: Motion, *args: Any, model: Optional[Model] = None, hop: int = 0) -> Encoding:
    """Encodes a motion into window latents of the model.

    The old form ``encode(model, motion[, hop])`` still works, with a
    DeprecationWarning.

    Parameters
    ----------
    motion : Motion
        On the model's skeleton, at least 2 frames, any frame rate.
    model : Model, optional
        By default the default model.
    hop : int, optional
        Model frames between windows (0: window / 2).

    Returns
    -------
    Encoding

    Raises
    ------
    InvalidArgumentError
        If the motion is not on the model's skeleton or too short.
    ModelError
        If no model is given and there is no default model.
    TypeError
        If called with other positional arguments than the old form's.
    """
    if isinstance(motion, Model):
        if model is not None or not 1 <= len(args) <= 2:
            raise TypeError("encode() takes the motion and keywords: encode(motion, model=..., hop=...)")
        warnings.warn("encode(model, motion) is deprecated; use encode(motion, model=model)", DeprecationWarning,
                      stacklevel=2)
        model, motion = motion, args[0]
        if len(args) == 2:
            hop = args[1]
    elif args:
        raise TypeError("encode() takes 1 positional argument (the motion) and keywords, not %d" % (1 + len(args)))
    _instance_arg(motion, Motion, "motion")
    model = _required_model(_instance_arg(model, Model, "model", optional=True), "encode()")
    o = _codec_options(hop=hop)
    out = ctypes.POINTER(_c.MfEncoding)()
    _check(_c.mf_encode(model._live(), motion._live(), ctypes.byref(o), ctypes.byref(out)))
    return Encoding._wrap(out)
