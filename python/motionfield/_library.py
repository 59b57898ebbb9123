"""What belongs to the library as a whole: its version and path, the threads,
the registered methods and the printing of messages."""

from __future__ import annotations

import ctypes
import functools
from typing import Dict, List, NamedTuple, Union

from . import _capi as _c
from ._args import _int_arg
from ._errors import _check


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
    """Sets the threads of the matrix products, for the whole process.

    Parameters
    ----------
    n : int
        Number of threads, 1..1024: the size of the BLAS library's own pool
        (the products with a network's weight run on the library's own
        kernels on the calling thread).
        Every task runs its numeric work on its calling thread and, until this
        is called, multiplies matrices there too, as the CLI's default. To run
        several tasks at once, call them from several threads.

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
    """The threads of the matrix products.

    Returns
    -------
    int
        The count set by set_num_threads(), else 1.

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
