"""Encoding: a motion as the model's window latents (encode()), and its decoding."""

from __future__ import annotations

import ctypes
import warnings
from typing import Any, List, Optional

import numpy as np
import numpy.typing as npt

from . import _capi as _c
from ._args import FloatArray, _float_arg, _instance_arg, _int_arg
from ._errors import InvalidArgumentError, _check
from ._handles import _f32_ptr, _Handle, _read_floats
from ._model import Model, _required_model
from ._motion import Motion


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
