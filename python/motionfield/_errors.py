"""The exceptions: one class per C status code (MF_ERROR_*), raised by _check()."""

from __future__ import annotations

from typing import Optional

from . import _capi as _c


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
