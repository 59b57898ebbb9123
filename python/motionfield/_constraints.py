"""Constraints beyond whole-pose keys, and solve(): a completion under them."""

from __future__ import annotations

import ctypes
import json
import os
from typing import Any, Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _capi as _c
from ._args import PathLike, RigMap, _float_arg, _float_array, _instance_arg, _int_arg, _int_list, _str_arg
from ._errors import InvalidArgumentError, _check
from ._handles import _f32_ptr, _Handle, _read_string
from ._model import Model, _task_model
from ._motion import Motion
from ._tasks import CancelToken, ProgressCallback, _task_doc, _TaskCall


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
          rig_map: Optional[RigMap] = None, max_iterations: int = 0, fallback: bool = True) -> Solution:
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
    {fallback}

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
    call = _TaskCall(method, seed, progress, cancel, rig_map, max_iterations, fallback)
    c = _constraints_arg(constraints, trajectory)
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
    handle = call.run(_c.mf_solve, _task_model(model, method), motion._live(), c._live(), alternatives,
                      out_type=_c.MfSolution)
    return _take_solution(handle)


def _constraints_arg(constraints: Union[Constraints, str, Dict[str, Any], None],
                     trajectory: Union[npt.ArrayLike, str, "os.PathLike[str]", None]) -> Constraints:
    """A new Constraints from solve()'s `constraints` and `trajectory` arguments."""
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
    if isinstance(trajectory, (str, os.PathLike)):
        c.load_trajectory(trajectory)
    elif isinstance(trajectory, tuple) and len(trajectory) == 2:
        c.add_trajectory(trajectory[0], trajectory[1])
    elif trajectory is not None:
        c.add_trajectory(trajectory)
    return c


def _take_solution(handle: Any) -> Solution:
    """The Solution of an mf_solution handle, which it destroys."""
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
