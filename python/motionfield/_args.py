"""Arguments: their types, their checks before they cross into C, and the
keyword-only calls that still accept the old positional forms."""

from __future__ import annotations

import functools
import inspect
import json
import math
import numbers
import os
import warnings
from typing import Any, Callable, Dict, Optional, Tuple, Type, TypeVar, Union

import numpy as np
import numpy.typing as npt

from ._errors import InvalidArgumentError

#: A file path: a string or an os.PathLike.
PathLike = Union[str, "os.PathLike[str]"]
#: A rig_map= argument: a dict {user joint: model joint or None}, a JSON file's path or JSON text.
RigMap = Union[Dict[str, Optional[str]], str, "os.PathLike[str]"]
FloatArray = npt.NDArray[np.float32]

_F = TypeVar("_F", bound=Callable[..., Any])


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


def _float_array(a: npt.ArrayLike, shape_tail: Tuple[int, ...], what: str) -> FloatArray:
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.ndim != 1 + len(shape_tail) or tuple(a.shape[1:]) != tuple(shape_tail):
        raise InvalidArgumentError("%s must have shape [N, %s], not %s" %
                                   (what, ", ".join(map(str, shape_tail)), list(a.shape)))
    return a


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
