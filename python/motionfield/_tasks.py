"""The tasks on a motion (in-betweening, gap filling, resampling, re-navigation,
the rig's description), their common options, progress and cancellation."""

from __future__ import annotations

import ctypes
import json
import os
from typing import Any, Callable, Dict, NamedTuple, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

from . import _capi as _c
from ._args import (FloatArray, PathLike, RigMap, _F, _float_arg, _instance_arg, _int_arg, _int_list,
                    _keywords_after, _rig_map_args, _str_arg)
from ._errors import InvalidArgumentError, _check
from ._handles import _f32_ptr, _Handle, _read_string
from ._model import Model, _required_model, _task_model
from ._motion import Motion

#: A progress callback: gets a Progress, returns True to cancel the task.
ProgressCallback = Callable[["Progress"], Optional[bool]]


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
    window : int
        The window being solved (0-based) of a long clip solved window by
        window (`iteration` and `max_iterations` are summed over the windows).
    window_count : int
        The number of windows; 0 (and `window` 0) for methods that do not
        work in windows.
    """

    iteration: int
    max_iterations: int
    energy: float
    window: int = 0
    window_count: int = 0


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


class _TaskCall:
    """The options struct of one task call, and its progress callback (kept
    alive for the call; exceptions it raises cancel the task and are re-raised)."""

    def __init__(self, method: Optional[str], seed: int, progress: Optional[ProgressCallback],
                 cancel: Optional[CancelToken], rig_map: Optional[RigMap] = None, max_iterations: int = 0,
                 fallback: bool = True) -> None:
        method = _str_arg(method, "method", optional=True)
        seed = _int_arg(seed, "seed", 0, 2**64 - 1)
        max_iterations = _int_arg(max_iterations, "max_iterations", 0, 100000)
        if not isinstance(fallback, bool):
            raise TypeError("fallback must be a bool, not %s" % type(fallback).__name__)
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
        self.options.no_fallback = 0 if fallback else 1
        self.error: Optional[BaseException] = None
        if progress is not None:
            def trampoline(_user_data: Any, p: Any) -> int:
                try:
                    c = p.contents
                    return 1 if progress(Progress(c.iteration, c.max_iterations, c.energy, c.window,
                                                  c.window_count)) else 0
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

_FALLBACK_DOC = """    fallback : bool, optional
        True (the default): where a latent solver ("nemf*") cannot reach the
        keys, that window is interpolated instead and ``warnings`` say so;
        False keeps the solver's result (mf_task_options.no_fallback)."""

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
        "    {task_raises}", _TASK_RAISES_DOC).replace("    {fallback}", _FALLBACK_DOC)
    return fn


@_task_doc
@_keywords_after(*_TASK_OPTIONS)
def inbetween(motion: Motion, keyframes: Sequence[int], *, method: Optional[str] = None,
              model: Optional[Model] = None, seed: int = 0, progress: Optional[ProgressCallback] = None,
              cancel: Optional[CancelToken] = None, rig_map: Optional[RigMap] = None,
              max_iterations: int = 0, fallback: bool = True) -> Motion:
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
    {fallback}

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
    call = _TaskCall(method, seed, progress, cancel, rig_map, max_iterations, fallback)
    return call.run(_c.mf_inbetween, _task_model(model, method), motion._live(),
                    keys.ctypes.data_as(ctypes.POINTER(ctypes.c_int32)), keys.size)


@_task_doc
@_keywords_after(*_TASK_OPTIONS)
def fill(motion: Motion, gap_begin: int, gap_end: int, *, method: Optional[str] = None,
         model: Optional[Model] = None, seed: int = 0, progress: Optional[ProgressCallback] = None,
         cancel: Optional[CancelToken] = None, rig_map: Optional[RigMap] = None, max_iterations: int = 0,
         fallback: bool = True) -> Motion:
    """Gap filling: frames gap_begin..gap_end-1 are produced, the others kept.

    Parameters
    ----------
    motion : Motion
        The input (the gap's frames are never read).
    gap_begin, gap_end : int
        The unknown frames, 1 <= gap_begin < gap_end <= frames - 1.
    {task_parameters}
    {fallback}

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
    call = _TaskCall(method, seed, progress, cancel, rig_map, max_iterations, fallback)
    return call.run(_c.mf_fill, _task_model(model, method), motion._live(), begin, end)


@_task_doc
@_keywords_after(*_TASK_OPTIONS)
def resample(motion: Motion, fps: float, *, method: Optional[str] = None, model: Optional[Model] = None,
             seed: int = 0, progress: Optional[ProgressCallback] = None, cancel: Optional[CancelToken] = None,
             rig_map: Optional[RigMap] = None, max_iterations: int = 0) -> Motion:
    """Resampling to another frame rate, keeping the time span.

    Without a method: "prior" with a model (the default one unless given),
    "quintic" (local quintic interpolation) without, as the CLI does.

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
        {"unit", "length_scale", "unit_detected", "unit_from_file", "joints", "map": {user joint:
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
