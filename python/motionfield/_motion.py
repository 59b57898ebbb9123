"""Motion (a skeleton and its frames): from arrays, BVH in and out, glTF out."""

from __future__ import annotations

import ctypes
import os
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from . import _capi as _c
from ._args import FloatArray, PathLike, _float_array, _int_list, _keywords_after
from ._errors import InvalidArgumentError, _check
from ._handles import _f32_ptr, _read_floats, _read_string, _Skeletal
from ._model import Model


def _bvh_options(length_scale: Optional[float]) -> Any:
    o = _c.MfBvhOptions()
    _check(_c.mf_bvh_options_init(ctypes.byref(o)))
    if length_scale is not None:
        o.length_scale = float(length_scale)
    return o


_LOAD_FORMATS = {None: 0, "auto": 0, "bvh": 1, "gltf": 2, "fbx": 3}  # MF_FORMAT_*


def _load_options(format: Optional[str], length_scale: Optional[float], animation: Union[str, int, None],
                  fps: Optional[float]) -> Any:
    if format not in _LOAD_FORMATS:
        raise InvalidArgumentError("format must be None, 'auto', 'bvh', 'gltf' or 'fbx', not %r" % (format,))
    o = _c.MfMotionLoadOptions()
    _check(_c.mf_motion_load_options_init(ctypes.byref(o)))
    o.format = _LOAD_FORMATS[format]
    if length_scale is not None:
        o.length_scale = float(length_scale)
    if isinstance(animation, str):
        o.animation = animation.encode()
    elif animation is not None:
        if isinstance(animation, bool) or not isinstance(animation, int) or animation < 0:
            raise InvalidArgumentError("animation must be a name or an index from 0, not %r" % (animation,))
        o.animation_index = animation
    if fps is not None:
        o.fps = float(fps)
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
    def load(cls, path: PathLike, units: Union[str, float, None] = None, animation: Union[str, int, None] = None,
             fps: Optional[float] = None, format: Optional[str] = None) -> "Motion":
        """Reads a motion file: BVH, glTF 2.0 (.glb, .gltf) or FBX.

        The format comes from the content, then the name (``format`` names
        it instead: "bvh", "gltf" or "fbx"). glTF and FBX files give the
        armature (the skin's joints, or the animated nodes) and one animation
        sampled from its first key to its last, with rotations relative to the
        rest pose (mf_motion_load in the C API documents the rules).

        Parameters
        ----------
        path : str or os.PathLike
            The file.
        units : str or float, optional
            BVH only, as for load_bvh. glTF is in metres, FBX in its file's unit.
        animation : str or int, optional
            glTF and FBX: the animation's name or index (default: the first).
        fps : float, optional
            glTF and FBX: the rate to sample at (default: the keys' rate).
        format : str, optional
            None or "auto", "bvh", "gltf", "fbx".

        Returns
        -------
        Motion

        Raises
        ------
        FileError
            If the file cannot be read.
        InvalidArgumentError
            If it is malformed (the message names the problem: truncated, no
            animation, no armature, two roots, NaN keys, ...).
        """
        out = ctypes.POINTER(_c.MfMotion)()
        o = _load_options(format, _units_scale(units, None), animation, fps)
        _check(_c.mf_motion_load(os.fspath(path).encode(), ctypes.byref(o), ctypes.byref(out)))
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
