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
    filled = mf.inbetween(walk, [0, 15, 30, 45, 60], method="interp")
    mf.resample(filled, 60.0).save_bvh("walk60.bvh")

Any humanoid rig works with every task, in its own unit (detected from the leg
length, or ``Motion.load_bvh(path, units="m")``) and frame rate: methods that
need the model retarget it to the model's rig and back. ``describe_rig(motion,
model)`` shows the map found; ``rig_map=`` (a dict, a JSON file or JSON text)
on the tasks overrides it.

The library is found through $MOTIONFIELD_LIBRARY, then next to this package,
then a build tree of the source checkout, then the system's library path.
Tasks release the GIL: several Python threads may run them at once on one
shared Model.
"""

import ctypes
import json
import os
from collections import namedtuple

import numpy as np

from . import _capi as _c

__all__ = [
    "Error", "InvalidArgumentError", "BufferTooSmallError", "FileError", "ModelError", "CancelledError",
    "InternalError", "UnsupportedError", "OutOfMemoryError",
    "version", "abi_version", "library_path", "set_num_threads", "get_num_threads",
    "Method", "methods", "default_method", "default_model_path",
    "Model", "Motion", "CancelToken", "Progress", "Encoding",
    "inbetween", "fill", "resample", "resample_frame_count", "encode",
    "renav", "load_path_csv", "describe_rig",
]

# ------------------------------------------------------------------ errors


class Error(Exception):
    """A motionfield call failed; ``status`` is the C status code."""

    status = None

    def __init__(self, message, status=None):
        super().__init__(message)
        if status is not None:
            self.status = status

    @property
    def status_name(self):
        return _c.mf_status_name(self.status).decode()


class InvalidArgumentError(Error, ValueError):
    status = _c.ERROR_INVALID_ARGUMENT


class BufferTooSmallError(Error):
    status = _c.ERROR_BUFFER_TOO_SMALL


class FileError(Error, OSError):
    status = _c.ERROR_IO


class ModelError(Error):
    status = _c.ERROR_MODEL


class CancelledError(Error):
    status = _c.ERROR_CANCELLED


class InternalError(Error):
    status = _c.ERROR_INTERNAL


class UnsupportedError(Error):
    status = _c.ERROR_UNSUPPORTED


class OutOfMemoryError(Error, MemoryError):
    status = _c.ERROR_OUT_OF_MEMORY


_ERRORS = {cls.status: cls for cls in (InvalidArgumentError, BufferTooSmallError, FileError, ModelError,
                                       CancelledError, InternalError, UnsupportedError, OutOfMemoryError)}


def _check(status):
    if status == _c.OK:
        return
    message = _c.mf_last_error_message().decode("utf-8", "replace")
    raise _ERRORS.get(status, Error)(message, status)


# ------------------------------------------------------------------ helpers


def _f32_ptr(a):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_float))


def _read_floats(getter, handle, shape):
    needed = ctypes.c_size_t(0)
    _check(getter(handle, None, 0, ctypes.byref(needed)))
    out = np.empty(needed.value, dtype=np.float32)
    _check(getter(handle, _f32_ptr(out), out.size, ctypes.byref(needed)))
    return out.reshape(shape)


def _read_string(getter, *args):
    needed = ctypes.c_size_t(0)
    _check(getter(*args, None, 0, ctypes.byref(needed)))
    buf = ctypes.create_string_buffer(needed.value)
    _check(getter(*args, buf, needed.value, ctypes.byref(needed)))
    return buf.value.decode("utf-8")


def _float_array(a, shape_tail, what):
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.ndim != 1 + len(shape_tail) or tuple(a.shape[1:]) != tuple(shape_tail):
        raise InvalidArgumentError("%s must have shape [N, %s], not %s" %
                                   (what, ", ".join(map(str, shape_tail)), list(a.shape)))
    return a


def _bvh_options(length_scale):
    o = _c.MfBvhOptions()
    _check(_c.mf_bvh_options_init(ctypes.byref(o)))
    if length_scale is not None:
        o.length_scale = float(length_scale)
    return o


def _units_scale(units, length_scale):
    """Metres per file unit for reading: None or "auto" -> None (detected), a
    unit name ("cm", "m", "mm", "in", "ft", "asf") or a number."""
    if length_scale is not None:
        if units is not None:
            raise InvalidArgumentError("give units or length_scale, not both")
        return length_scale
    if units is None or units == "auto":
        return None
    if isinstance(units, str):
        v = ctypes.c_double(0)
        _check(_c.mf_length_unit_scale(units.encode(), ctypes.byref(v)))
        return v.value
    return float(units)


def _rig_map_args(rig_map):
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
    raise InvalidArgumentError("rig_map must be a dict, a JSON file's path or JSON text, not %s" %
                               type(rig_map).__name__)


# ------------------------------------------------------------------ library-wide


def version():
    """The library's version string, e.g. "0.1.0"."""
    return _c.mf_version_string().decode()


def abi_version():
    return int(_c.mf_abi_version())


def library_path():
    """Path of the loaded libmotionfield.so."""
    return _c.library_path


def set_num_threads(n):
    """Intra-op threads of the numeric work, for the whole process (1..1024)."""
    _check(_c.mf_set_num_threads(int(n)))


def get_num_threads():
    n = ctypes.c_int32(0)
    _check(_c.mf_get_num_threads(ctypes.byref(n)))
    return n.value


Method = namedtuple("Method", "name description needs_model completes resamples")


def methods():
    """Every registered method, as Method tuples."""
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


def default_method(model=None):
    """The method used when none is named (it may depend on the model)."""
    name = ctypes.c_char_p()
    _check(_c.mf_default_method(model._handle if model is not None else None, ctypes.byref(name)))
    return name.value.decode()


def default_model_path():
    """Path of the default model, or None if there is none."""
    path = _read_string(_c.mf_model_default_path)
    return path or None


# ------------------------------------------------------------------ handles


class _Handle:
    _destroy = None

    def __init__(self, handle):
        self._handle = handle

    def close(self):
        """Frees the C object now (otherwise when garbage-collected)."""
        if getattr(self, "_handle", None):
            type(self)._destroy(self._handle)
            self._handle = None

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _live(self):
        if not self._handle:
            raise InvalidArgumentError("%s is closed" % type(self).__name__)
        return self._handle


class Model(_Handle):
    """A loaded prior. Immutable; share one between threads."""

    _destroy = staticmethod(_c.mf_model_destroy)

    def __init__(self, path=None):
        """Loads a model file; path None loads the default model."""
        handle = ctypes.POINTER(_c.MfModel)()
        _check(_c.mf_model_load(None if path is None else str(path).encode(), ctypes.byref(handle)))
        super().__init__(handle)

    @classmethod
    def from_bytes(cls, data):
        data = bytes(data)
        handle = ctypes.POINTER(_c.MfModel)()
        _check(_c.mf_model_load_from_memory(data, len(data), ctypes.byref(handle)))
        self = cls.__new__(cls)
        _Handle.__init__(self, handle)
        return self

    def with_inbetweener(self, path):
        """A new Model: this one's prior and transformers plus the transformer
        in-betweener file at `path` (kind "twostage" or "citl", read from the
        file). Model(path) already loads motionfield-twostage.mfm and
        motionfield-citl.mfm found next to the prior's file."""
        handle = ctypes.POINTER(_c.MfModel)()
        _check(_c.mf_model_with_inbetweener(self._live(), str(path).encode(), ctypes.byref(handle)))
        model = type(self).__new__(type(self))
        _Handle.__init__(model, handle)
        return model

    def has_inbetweener(self, kind):
        """True when the transformer of `kind` ("twostage": methods context,
        detail, nemf-context, nemf-detail; "citl": citl, nemf-citl) is loaded."""
        v = ctypes.c_int32(0)
        _check(_c.mf_model_has_inbetweener(self._live(), str(kind).encode(), ctypes.byref(v)))
        return v.value != 0

    def _i32(self, getter):
        v = ctypes.c_int32(0)
        _check(getter(self._live(), ctypes.byref(v)))
        return v.value

    @property
    def joint_count(self):
        return self._i32(_c.mf_model_get_joint_count)

    @property
    def joint_names(self):
        return [_read_string(_c.mf_model_get_joint_name, self._live(), j) for j in range(self.joint_count)]

    @property
    def parents(self):
        n = self.joint_count
        out = (ctypes.c_int32 * n)()
        _check(_c.mf_model_get_parents(self._live(), out, n, None))
        return np.array(out, dtype=np.int32)

    @property
    def offsets(self):
        return _read_floats(_c.mf_model_get_offsets, self._live(), (-1, 3))

    @property
    def fps(self):
        v = ctypes.c_double(0)
        _check(_c.mf_model_get_fps(self._live(), ctypes.byref(v)))
        return v.value

    @property
    def window(self):
        return self._i32(_c.mf_model_get_window)

    @property
    def latent_sizes(self):
        """(local_size, global_size)."""
        zl, zg = ctypes.c_int32(0), ctypes.c_int32(0)
        _check(_c.mf_model_get_latent_sizes(self._live(), ctypes.byref(zl), ctypes.byref(zg)))
        return zl.value, zg.value


class Motion(_Handle):
    """A skeleton with per-frame local rotations and root positions. Immutable."""

    _destroy = staticmethod(_c.mf_motion_destroy)

    def __init__(self, *args, **kwargs):
        raise TypeError("use Motion.from_arrays, Motion.load_bvh or Motion.from_bvh_text")

    @classmethod
    def _wrap(cls, handle):
        self = cls.__new__(cls)
        _Handle.__init__(self, handle)
        return self

    @classmethod
    def from_arrays(cls, rotations, root_positions, fps, joint_names=None, parents=None, offsets=None, model=None,
                    like=None):
        """A motion from arrays: rotations [F, J, 4] (w, x, y, z), root_positions
        [F, 3] in metres, on the skeleton given by joint_names/parents/offsets
        ([J, 3], metres), by a Model (`model`) or by another Motion (`like`,
        whose BVH layout the new motion also keeps)."""
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
            if parents is None or offsets is None:
                raise InvalidArgumentError("joint_names needs parents and offsets")
            if len(joint_names) != joints or len(parents) != joints:
                raise InvalidArgumentError("joint_names and parents must have one entry per joint (%d)" % joints)
            names = (ctypes.c_char_p * joints)(*[str(n).encode() for n in joint_names])
            par = (ctypes.c_int32 * joints)(*[int(p) for p in parents])
            off = _float_array(offsets, (3,), "offsets")
            if off.shape[0] != joints:
                raise InvalidArgumentError("offsets must have shape [%d, 3], not %s" % (joints, list(off.shape)))
            _check(_c.mf_motion_create(joints, names, par, _f32_ptr(off), frames, float(fps), _f32_ptr(rot),
                                       _f32_ptr(root), ctypes.byref(out)))
        return cls._wrap(out)

    @classmethod
    def load_bvh(cls, path, units=None, length_scale=None):
        """Reads a BVH file. units: None or "auto" (detected from the leg
        length; centimetres when no legs are found), "cm", "m", "mm", "in",
        "ft", "asf" or metres per file unit (a number; length_scale= is the
        same). The motion remembers it (length_scale) and writes in it."""
        out = ctypes.POINTER(_c.MfMotion)()
        o = _bvh_options(_units_scale(units, length_scale))
        _check(_c.mf_motion_load_bvh(str(path).encode(), ctypes.byref(o), ctypes.byref(out)))
        return cls._wrap(out)

    @classmethod
    def from_bvh_text(cls, text, units=None, length_scale=None):
        data = text.encode() if isinstance(text, str) else bytes(text)
        out = ctypes.POINTER(_c.MfMotion)()
        o = _bvh_options(_units_scale(units, length_scale))
        _check(_c.mf_motion_load_bvh_from_memory(data, len(data), ctypes.byref(o), ctypes.byref(out)))
        return cls._wrap(out)

    def save_bvh(self, path, length_scale=None):
        """Writes BVH (atomically), keeping the layout of the BVH it came from."""
        o = _bvh_options(length_scale)
        _check(_c.mf_motion_save_bvh(self._live(), str(path).encode(), ctypes.byref(o)))

    def to_bvh_text(self, length_scale=None):
        o = _bvh_options(length_scale)
        return _read_string(_c.mf_motion_save_bvh_to_memory, self._live(), ctypes.byref(o))

    def _i32(self, getter):
        v = ctypes.c_int32(0)
        _check(getter(self._live(), ctypes.byref(v)))
        return v.value

    def _f64(self, getter):
        v = ctypes.c_double(0)
        _check(getter(self._live(), ctypes.byref(v)))
        return v.value

    @property
    def frame_count(self):
        return self._i32(_c.mf_motion_get_frame_count)

    @property
    def joint_count(self):
        return self._i32(_c.mf_motion_get_joint_count)

    @property
    def fps(self):
        return self._f64(_c.mf_motion_get_fps)

    @property
    def length_scale(self):
        """Metres per file unit the motion was read with (given or detected);
        0.01 for motions from arrays. Task results keep their input's."""
        return self._f64(_c.mf_motion_get_length_scale)

    @property
    def warnings(self):
        """What the task that made this motion wants the caller to know although
        it succeeded (e.g. a resampling whose frame count was rounded down), one
        sentence per line; "" if nothing."""
        return _read_string(_c.mf_motion_get_warnings, self._live())

    @property
    def frame_time(self):
        """Seconds between frames as a BVH file of this motion says them."""
        return self._f64(_c.mf_motion_get_frame_time)

    @property
    def joint_names(self):
        return [_read_string(_c.mf_motion_get_joint_name, self._live(), j) for j in range(self.joint_count)]

    @property
    def parents(self):
        n = self.joint_count
        out = (ctypes.c_int32 * n)()
        _check(_c.mf_motion_get_parents(self._live(), out, n, None))
        return np.array(out, dtype=np.int32)

    @property
    def offsets(self):
        return _read_floats(_c.mf_motion_get_offsets, self._live(), (-1, 3))

    @property
    def rotations(self):
        """[frames, joints, 4] float32 local rotations (w, x, y, z)."""
        return _read_floats(_c.mf_motion_get_rotations, self._live(), (self.frame_count, self.joint_count, 4))

    @property
    def root_positions(self):
        """[frames, 3] float32 root positions, metres."""
        return _read_floats(_c.mf_motion_get_root_positions, self._live(), (-1, 3))

    @property
    def global_positions(self):
        """[frames, joints, 3] float32 joint positions (forward kinematics), metres."""
        return _read_floats(_c.mf_motion_get_global_positions, self._live(),
                            (self.frame_count, self.joint_count, 3))

    def __repr__(self):
        if not self._handle:
            return "<motionfield.Motion (closed)>"
        return "<motionfield.Motion %d frames at %g fps, %d joints>" % (self.frame_count, self.fps, self.joint_count)


class CancelToken(_Handle):
    """Stops a running task from any thread: token.cancel()."""

    _destroy = staticmethod(_c.mf_cancel_token_destroy)

    def __init__(self):
        handle = ctypes.POINTER(_c.MfCancelToken)()
        _check(_c.mf_cancel_token_create(ctypes.byref(handle)))
        super().__init__(handle)

    def cancel(self):
        _check(_c.mf_cancel_token_cancel(self._live()))

    def reset(self):
        _check(_c.mf_cancel_token_reset(self._live()))

    @property
    def cancelled(self):
        v = ctypes.c_int32(0)
        _check(_c.mf_cancel_token_is_cancelled(self._live(), ctypes.byref(v)))
        return bool(v.value)


Progress = namedtuple("Progress", "iteration max_iterations energy")

# ------------------------------------------------------------------ tasks


class _TaskCall:
    """The options struct of one task call, and its progress callback (kept
    alive for the call; exceptions it raises cancel the task and are re-raised)."""

    def __init__(self, method, seed, progress, cancel, rig_map=None):
        self.options = _c.MfTaskOptions()
        _check(_c.mf_task_options_init(ctypes.byref(self.options)))
        self._method = method.encode() if method else None
        self.options.method = self._method
        text, path = _rig_map_args(rig_map)
        self._rig_map = (text.encode() if text else None, path.encode() if path else None)
        self.options.rig_map, self.options.rig_map_path = self._rig_map
        self.options.seed = int(seed)
        self.error = None
        if progress is not None:
            def trampoline(_user_data, p):
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

    def run(self, fn, *args):
        out = ctypes.POINTER(_c.MfMotion)()
        status = fn(*args, ctypes.byref(self.options), ctypes.byref(out))
        if self.error is not None:
            raise self.error
        _check(status)
        return Motion._wrap(out)


def _model_handle(model):
    return model._live() if model is not None else None


def inbetween(motion, keyframes, method=None, model=None, seed=0, progress=None, cancel=None, rig_map=None):
    """Keyframe in-betweening: the frames in `keyframes` (0-based, strictly
    increasing, at least two) are kept, every other frame is produced.

    progress(Progress) is called now and then; returning True cancels (the
    call then raises CancelledError). cancel: a CancelToken. rig_map: for a
    motion on another rig than the model's, a dict {user joint: model joint or
    None}, a JSON file's path or JSON text overriding the automatic map (see
    describe_rig)."""
    keys = np.ascontiguousarray(keyframes, dtype=np.int32).reshape(-1)
    call = _TaskCall(method, seed, progress, cancel, rig_map)
    return call.run(_c.mf_inbetween, _model_handle(model), motion._live(),
                    keys.ctypes.data_as(ctypes.POINTER(ctypes.c_int32)), keys.size)


def fill(motion, gap_begin, gap_end, method=None, model=None, seed=0, progress=None, cancel=None, rig_map=None):
    """Gap filling: frames gap_begin..gap_end-1 are produced, the others kept."""
    call = _TaskCall(method, seed, progress, cancel, rig_map)
    return call.run(_c.mf_fill, _model_handle(model), motion._live(), int(gap_begin), int(gap_end))


def resample(motion, fps, method=None, model=None, seed=0, progress=None, cancel=None, rig_map=None):
    """Resampling to `fps`, keeping the time span (see resample_frame_count)."""
    call = _TaskCall(method, seed, progress, cancel, rig_map)
    return call.run(_c.mf_resample, _model_handle(model), motion._live(), float(fps))


def resample_frame_count(frames, fps_in, fps_out):
    """(frame count, rounded): (frames - 1) * fps_out / fps_in + 1, rounded
    down (rounded=True) unless within 1e-5 relative of an integer."""
    n, rounded = ctypes.c_int32(0), ctypes.c_int32(0)
    _check(_c.mf_resample_frame_count(int(frames), float(fps_in), float(fps_out), ctypes.byref(n),
                                      ctypes.byref(rounded)))
    return n.value, bool(rounded.value)


def load_path_csv(path):
    """Reads a path CSV (one "x,z" pair per line, metres; an optional header
    "x,z"; blank lines and lines starting with # skipped) into a float32 array
    [points, 2]."""
    name = str(path).encode()
    needed = ctypes.c_size_t(0)
    _check(_c.mf_path_load_csv(name, None, 0, ctypes.byref(needed)))
    out = np.empty(needed.value, dtype=np.float32)
    _check(_c.mf_path_load_csv(name, _f32_ptr(out), out.size, ctypes.byref(needed)))
    return out.reshape(-1, 2)


def renav(reference, path, model, method=None, polyline=False, frames=0, fps=0.0, seed=0, progress=None,
          cancel=None, rig_map=None):
    """Re-navigation: a motion in the style of `reference` (on any humanoid
    rig; rig_map as in inbetween()) whose root follows `path`, an array
    [points, 2] of ground (x, z) positions in metres. By default one point per output frame at `fps` (0:
    the reference's frame rate); with polyline=True the points are the
    vertices of a polyline walked at constant speed, in `frames` frames (0:
    at the reference's mean ground speed). method: "nemf" (L-BFGS, the
    default) or "nemf-adam". Needs a Model. progress/cancel as in inbetween()."""
    xz = np.ascontiguousarray(path, dtype=np.float32)
    if xz.ndim != 2 or xz.shape[1] != 2:
        raise InvalidArgumentError("path must have shape [points, 2], not %s" % list(xz.shape))
    o = _c.MfRenavOptions()
    _check(_c.mf_renav_options_init(ctypes.byref(o)))
    o.path_kind = _c.PATH_POLYLINE if polyline else _c.PATH_PER_FRAME
    o.frame_count = int(frames)
    o.fps = float(fps)
    call = _TaskCall(method, seed, progress, cancel, rig_map)
    return call.run(lambda *args: _c.mf_renav(*args[:4], ctypes.byref(o), *args[4:]), _model_handle(model),
                    reference._live(), _f32_ptr(xz), xz.shape[0])


def describe_rig(motion, model, rig_map=None):
    """How `motion`'s rig is read and mapped onto `model`'s, as a dict:
    {"unit", "length_scale", "unit_detected", "joints", "map": {user joint:
    model joint}, "how": {model joint: "name" | "shape" | "map file"},
    "unmapped_user_joints", "model_joints", "retargeting"} (mf_rig_describe).
    rig_map as in inbetween(). Raises InvalidArgumentError with the reason
    when the rig cannot be mapped."""
    text, path = _rig_map_args(rig_map)
    if path is not None:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    try:
        out = _read_string(_c.mf_rig_describe, model._live(), motion._live(), text.encode() if text else None)
    except InvalidArgumentError as e:
        if path is None:
            raise
        raise InvalidArgumentError("%s: %s" % (path, e), e.status) from None
    return json.loads(out)


# ------------------------------------------------------------------ encode, decode

_ROOTS = {"prior": _c.ROOT_FROM_PRIOR, "input": _c.ROOT_FROM_INPUT}


def _codec_options(hop=0, root="prior"):
    o = _c.MfCodecOptions()
    _check(_c.mf_codec_options_init(ctypes.byref(o)))
    o.hop = int(hop)
    if root not in _ROOTS:
        raise InvalidArgumentError("root must be 'prior' or 'input', not %r" % (root,))
    o.root_source = _ROOTS[root]
    return o


class Encoding(_Handle):
    """A motion encoded by a model as window latents (see encode())."""

    _destroy = staticmethod(_c.mf_encoding_destroy)

    def __init__(self, *args, **kwargs):
        raise TypeError("use motionfield.encode(model, motion)")

    @classmethod
    def _wrap(cls, handle):
        self = cls.__new__(cls)
        _Handle.__init__(self, handle)
        return self

    @property
    def window_count(self):
        v = ctypes.c_int32(0)
        _check(_c.mf_encoding_get_window_count(self._live(), ctypes.byref(v)))
        return v.value

    @property
    def duration(self):
        """Seconds from the first to the last frame of the encoded motion."""
        v = ctypes.c_double(0)
        _check(_c.mf_encoding_get_duration(self._live(), ctypes.byref(v)))
        return v.value

    @property
    def window_times(self):
        """[windows] float64 start time of each window, seconds."""
        n = self.window_count
        out = np.empty(n, dtype=np.float64)
        _check(_c.mf_encoding_get_window_times(self._live(), out.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n,
                                               None))
        return out

    @property
    def local_latents(self):
        """[windows, local_size] float32."""
        return _read_floats(_c.mf_encoding_get_local_latents, self._live(), (self.window_count, -1))

    @property
    def global_latents(self):
        """[windows, global_size] float32."""
        return _read_floats(_c.mf_encoding_get_global_latents, self._live(), (self.window_count, -1))

    def with_latents(self, local=None, global_=None):
        """A copy with other latents (arrays shaped like local_latents / global_latents)."""
        args, keep = [], []
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

    def decode(self, fps, frame_count=0, root="prior"):
        """Frames at times i / fps, i < frame_count (0: the encoded time span)."""
        o = _codec_options(root=root)
        out = ctypes.POINTER(_c.MfMotion)()
        _check(_c.mf_decode(self._live(), float(fps), int(frame_count), ctypes.byref(o), ctypes.byref(out)))
        return Motion._wrap(out)

    def decode_times(self, times, fps, root="prior"):
        """One frame per time (seconds from the first frame, any order)."""
        t = np.ascontiguousarray(times, dtype=np.float64).reshape(-1)
        o = _codec_options(root=root)
        out = ctypes.POINTER(_c.MfMotion)()
        _check(_c.mf_decode_times(self._live(), t.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), t.size,
                                  float(fps), ctypes.byref(o), ctypes.byref(out)))
        return Motion._wrap(out)


def encode(model, motion, hop=0):
    """Encodes `motion` (on the model's skeleton, >= 2 frames, any fps) into
    window latents; hop: model frames between windows (0: window / 2)."""
    o = _codec_options(hop=hop)
    out = ctypes.POINTER(_c.MfEncoding)()
    _check(_c.mf_encode(model._live(), motion._live(), ctypes.byref(o), ctypes.byref(out)))
    return Encoding._wrap(out)
