"""transition(): two clips in, one transition out (mf_transition)."""

from __future__ import annotations

import ctypes
import os
from typing import Any, Dict, List, NamedTuple, Optional, Union

import numpy.typing as npt

from . import _capi as _c
from ._args import RigMap, _instance_arg, _int_arg, _str_arg
from ._constraints import Constraints, _constraints_arg, _take_solution
from ._errors import InvalidArgumentError, _check
from ._model import Model, _task_model
from ._motion import Motion
from ._tasks import CancelToken, ProgressCallback, _task_doc, _TaskCall

_PLACES = {"auto": _c.PLACE_AUTO, "keep": _c.PLACE_KEEP}


class Transition(NamedTuple):
    """What transition() returns.

    Attributes
    ----------
    motions : list of Motion
        The method's transition first, then the alternatives: each the whole
        clip (A's frames 0..from_frame, the generated frames, B's frames from
        to_frame), or only the generated frames with ``only_transition``.
    frames : int
        The generated frames, as given or chosen.
    first_frame : int
        The first generated frame in the whole clip (A's last kept frame + 1).
    warnings : list of str
        What the library wants the caller to know: the chosen length, B
        resampled or mapped onto A's rig, constraints that could not hold.
    method : str
        The method that ran.
    report : dict
        How well each solution meets the constraints (as Solution.report).
    """

    motions: List[Motion]
    frames: int
    first_frame: int
    warnings: List[str]
    method: str
    report: Dict[str, Any]

    @property
    def motion(self) -> Motion:
        """The method's transition (motions[0])."""
        return self.motions[0]


@_task_doc
def transition(a: Motion, b: Motion, frames: Optional[int] = None, from_frame: Optional[int] = None,
               to_frame: Optional[int] = None, place: str = "auto", only_transition: bool = False, *,
               constraints: Union[Constraints, str, Dict[str, Any], None] = None,
               trajectory: Union[npt.ArrayLike, str, "os.PathLike[str]", None] = None, alternatives: int = 0,
               method: Optional[str] = None, model: Optional[Model] = None, seed: int = 0,
               progress: Optional[ProgressCallback] = None, cancel: Optional[CancelToken] = None,
               rig_map: Optional[RigMap] = None, max_iterations: int = 0, fallback: bool = True) -> Transition:
    """The end of clip `a` and the start of clip `b` with generated frames between them.

    ``transition(walk, run, 20).motion`` is ``motionfield transition walk.bvh
    run.bvh -o OUT --frames 20``: a's frames 0..from_frame, 20 generated
    frames, b's frames from to_frame, on a's rig, unit and frame rate (b may
    list the same joints in another order, or name them otherwise on the same
    hierarchy, and is resampled to a's rate). Both parts come out exactly (b's
    after its placement).

    Parameters
    ----------
    a, b : Motion
        The two clips, at least two frames each.
    frames : int, optional
        Generated frames (1..600); None chooses them from the change of pose
        (and, with place="keep", the distance between the clips): 10..60 at 30
        fps, reported in ``frames`` and ``warnings``.
    from_frame : int, optional
        A's last kept frame (default: its last; negative counts from the end).
    to_frame : int, optional
        B's first kept frame (default 0; negative counts from the end).
    place : str
        "auto": b is moved and turned on the ground to continue a's end
        (facing alike, the root carried on at the mean of the two clips'
        ground speeds at the seams); "keep": b stays where it is.
    only_transition : bool
        Return only the generated frames.
    constraints : Constraints, str or dict, optional
        More constraints as for solve(); their frames are frames of the whole
        output clip.
    trajectory : array [N, 5], (frames [N], rows [N, 4]), or a CSV path, optional
        A ground trajectory as for solve() (latent solvers only).
    alternatives : int
        More transitions (0..16) from other starts, deterministic for `seed`.
    {task_parameters}
    {fallback}

    Returns
    -------
    Transition
        The motions (the method's first), the frame count and where the
        transition starts, the warnings, the method and the report.

    Raises
    ------
    {task_raises}
    """
    _instance_arg(a, Motion, "a")
    _instance_arg(b, Motion, "b")
    options = _c.MfTransitionOptions()
    _check(_c.mf_transition_options_init(ctypes.byref(options)))
    if frames is not None:
        options.frames = _int_arg(frames, "frames", 1, 600)
    if from_frame is not None:
        options.from_frame = _int_arg(from_frame, "from_frame")
    if to_frame is not None:
        options.to_frame = _int_arg(to_frame, "to_frame")
    place_name = _str_arg(place, "place")
    if place_name not in _PLACES:
        raise InvalidArgumentError("place must be \"auto\" or \"keep\", not %r" % (place,))
    options.place = _PLACES[place_name]  # type: ignore[index]
    if not isinstance(only_transition, bool):
        raise TypeError("only_transition must be a bool, not %s" % type(only_transition).__name__)
    options.only_transition = 1 if only_transition else 0
    alternatives = _int_arg(alternatives, "alternatives", 0, 16)
    given = constraints is not None or trajectory is not None
    c = _constraints_arg(constraints, trajectory) if given else None
    call = _TaskCall(method, seed, progress, cancel, rig_map, max_iterations, fallback)
    handle = call.run(_c.mf_transition, _task_model(model, method), a._live(), b._live(), ctypes.byref(options),
                      c._live() if c is not None else None, alternatives, out_type=_c.MfSolution)
    n, first = ctypes.c_int32(0), ctypes.c_int32(0)
    status = _c.mf_solution_get_transition(handle, ctypes.byref(n), ctypes.byref(first))
    solution = _take_solution(handle)
    _check(status)
    return Transition(solution.motions, n.value, first.value, solution.warnings, solution.method, solution.report)
