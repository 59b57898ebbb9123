"""Ownership of the C handles (_Handle: freed once, by close() or the garbage
collector) and the reading of the C API's sized buffers."""

from __future__ import annotations

import ctypes
from typing import Any, List, Tuple, Type, TypeVar

import numpy as np
import numpy.typing as npt

from ._args import FloatArray
from ._errors import InvalidArgumentError, _check


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
