"""The jobs of ``motionfield batch`` through the library's job runner.

The JSON-lines job format (one job per line: ``{"task": "inbetween", "in":
..., "out": ..., ...}``, docs/CLI.md), its checks, the run of a job and its
messages live in the library (``mf_job_runner``, motionfield.h "batch jobs"),
which the CLI uses too: a line gives the same outputs, the same stderr lines
("motionfield: FILE line N (id X): error: ...") and the same ``--json``
summary here as in ``motionfield batch``. This module adds what a runner of
batch files elsewhere needs around it (``python3 -m motionfield.dask``):
reading a batch file as the CLI reads it and the batch's last line and exit
code.
"""

from __future__ import annotations

import ctypes
import dataclasses
import os
import stat
from typing import Iterable, List, Optional, Sequence, Tuple

from . import _capi as _c
from . import _check, printable_text
from ._handles import _read_string

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2

#: The largest batch file read (the CLI's kMaxCliTextFileBytes).
MAX_BATCH_FILE_BYTES = 64 << 20


class InputError(Exception):
    """A batch file that cannot be read (exit code 2); the message is for the user as is."""


@dataclasses.dataclass
class JobResult:
    """What a job run said (picklable: a Dask worker sends it back).

    Attributes
    ----------
    exit_code : int
        0 ok, 2 bad input, 1 internal error.
    messages : bytes
        The job's stderr lines as the CLI prints them, each ending in a newline.
    json : bytes
        Its ``--json`` summary line, without the newline.
    """

    exit_code: int
    messages: bytes
    json: bytes


def _read_bytes(getter, handle) -> bytes:  # type: ignore[no-untyped-def]
    needed = ctypes.c_size_t(0)
    _check(getter(handle, None, 0, ctypes.byref(needed)))
    buf = ctypes.create_string_buffer(needed.value)
    _check(getter(handle, buf, needed.value, ctypes.byref(needed)))
    return buf.raw[:max(needed.value - 1, 0)]


def _take_result(handle) -> JobResult:  # type: ignore[no-untyped-def]
    try:
        code = ctypes.c_int32(0)
        _check(_c.mf_job_result_get_exit_code(handle, ctypes.byref(code)))
        return JobResult(code.value, _read_bytes(_c.mf_job_result_get_messages, handle),
                         _read_bytes(_c.mf_job_result_get_json, handle))
    finally:
        _c.mf_job_result_destroy(handle)


def _path(p: str) -> bytes:
    return os.fsencode(p)


class CheckedJob:
    """One line parsed and its files checked by a JobRunner (check_line)."""

    _destroy = _c.mf_job_destroy  # kept by the class: module globals are gone at interpreter exit

    def __init__(self, handle) -> None:  # type: ignore[no-untyped-def]
        self._handle = handle

    @property
    def runnable(self) -> bool:
        """Whether the job will run (else running it gives its failure)."""
        return bool(_c.mf_job_is_runnable(self._handle))

    @property
    def has_load_warnings(self) -> bool:
        """Whether the model's load warnings go with this job (the first runnable job naming no method)."""
        return bool(_c.mf_job_has_load_warnings(self._handle))

    def __del__(self) -> None:
        if getattr(self, "_handle", None):
            type(self)._destroy(self._handle)
            self._handle = None


class JobRunner:
    """The library's job runner (mf_job_runner): the settings the jobs of one
    run share and the model they load once.

    Parameters
    ----------
    threads : int
        Intra-op threads, named in the ``--verbose`` line (set them with
        motionfield.set_num_threads).
    model : str
        The model file; "" for the default model, loaded on first need.
    inbetweeners : sequence of str
        Transformer files added to the model (``--twostage``, ``--citl``).
    rig_map, units : str
        The rig map file and length unit of every job without its own.
    verbose, quiet : bool
        A line of what each job ran; no warnings.
    preload_model : bool
        check_line loads the model each job needs (``batch --jobs N``).

    Raises
    ------
    motionfield.Error
        When `model` does not load, or `units` is no unit.
    """

    _destroy = _c.mf_job_runner_destroy

    def __init__(self, threads: int = 1, model: str = "", inbetweeners: Sequence[str] = (), rig_map: str = "",
                 units: str = "", verbose: bool = False, quiet: bool = False, preload_model: bool = False) -> None:
        o = _c.MfJobRunnerOptions()
        _check(_c.mf_job_runner_options_init(ctypes.byref(o)))
        o.flags = ((_c.JOB_VERBOSE if verbose else 0) | (_c.JOB_QUIET if quiet else 0) |
                   (_c.JOB_PRELOAD_MODEL if preload_model else 0))
        o.threads = threads
        o.model = _path(model)
        files = (ctypes.c_char_p * max(len(inbetweeners), 1))(*[_path(f) for f in inbetweeners])
        o.inbetweeners = files
        o.inbetweener_count = len(inbetweeners)
        o.rig_map = _path(rig_map) if rig_map else None
        o.units = units.encode("utf-8")
        handle = _c._runner()
        _check(_c.mf_job_runner_create(ctypes.byref(o), ctypes.byref(handle)))
        self._handle = handle

    def __del__(self) -> None:
        if getattr(self, "_handle", None):
            type(self)._destroy(self._handle)
            self._handle = None

    def check_line(self, text: bytes, line: int, batch_path: str) -> CheckedJob:
        """Parses line `line` (1-based) of `batch_path` and checks its files
        against every line this runner checked before."""
        handle = _c._job()
        _check(_c.mf_job_runner_check_line(self._handle, text, len(text), line, _path(batch_path),
                                           ctypes.byref(handle)))
        return CheckedJob(handle)

    def run(self, job: CheckedJob) -> JobResult:
        """Runs a checked job (once)."""
        handle = _c._result()
        _check(_c.mf_job_run(self._handle, job._handle, None, ctypes.byref(handle)))
        return _take_result(handle)

    def run_line(self, text: bytes, line: int, batch_path: str, load_warnings: bool = False) -> JobResult:
        """Parses, checks and runs one line on its own (its batch checked elsewhere)."""
        o = _c.MfJobRunOptions()
        _check(_c.mf_job_run_options_init(ctypes.byref(o)))
        o.flags = _c.JOB_LOAD_WARNINGS if load_warnings else 0
        handle = _c._result()
        _check(_c.mf_job_runner_run_line(self._handle, text, len(text), line, _path(batch_path), ctypes.byref(o),
                                         ctypes.byref(handle)))
        return _take_result(handle)

    def load_model(self) -> None:
        """Loads the model now if not yet (the named one, else the default one)."""
        _check(_c.mf_job_runner_load_model(self._handle, None))

    @property
    def model_path(self) -> str:
        """The loaded model's path ("" before one is loaded)."""
        return os.fsdecode(_read_bytes(_c.mf_job_runner_get_model_path, self._handle))


def read_text_file(path: str, what: str, max_bytes: int = MAX_BATCH_FILE_BYTES) -> bytes:
    """A file's bytes as the CLI's read_text_file reads them: directories,
    devices and files over `max_bytes` refused with InputError."""
    try:
        st = os.stat(path)
    except OSError as e:
        raise InputError("cannot open the %s %s: %s" % (what, path, e.strerror)) from None
    cannot = "cannot read the %s %s: " % (what, path)
    if stat.S_ISDIR(st.st_mode):
        raise InputError(cannot + "it is a directory")
    if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode):
        raise InputError(cannot + "it is a device, not a file")
    too_large = cannot + "larger than the limit of %d MiB" % (max_bytes >> 20)
    if stat.S_ISREG(st.st_mode) and st.st_size > max_bytes:
        raise InputError(too_large)
    try:
        with open(path, "rb") as f:
            data = f.read(max_bytes + 1)
    except OSError as e:
        raise InputError(cannot + (e.strerror or str(e))) from None
    if len(data) > max_bytes:
        raise InputError(too_large)
    return data


def read_lines(path: str) -> List[Tuple[int, bytes]]:
    """The non-blank lines of a batch file with their 1-based numbers
    (std::getline's split; a UTF-8 BOM dropped), as ``motionfield batch`` reads them."""
    data = read_text_file(path, "batch file")
    if not data:
        return []
    lines = data.split(b"\n")
    if data.endswith(b"\n"):
        lines.pop()
    if lines[0].startswith(b"\xef\xbb\xbf"):
        lines[0] = lines[0][3:]
    return [(i + 1, line) for i, line in enumerate(lines) if line.strip(b" \t\r\n")]


def printable(text: str) -> str:
    """`text` safe to print (mf_printable_text), as the CLI prints every message."""
    try:
        return printable_text(text)
    except Exception:  # noqa: BLE001 (out of memory: say so rather than print raw bytes)
        return "(a message that could not be made printable)"


def summary(path: str, exit_codes: Iterable[int], verbose: bool, quiet: bool,
            progress_shown: bool) -> Tuple[str, int]:
    """The batch's last stderr line (when the CLI prints one) and its exit code (mf_job_batch_summary)."""
    listed = [int(c) for c in exit_codes]
    codes = (ctypes.c_int32 * len(listed))(*listed)
    flags = (_c.JOB_VERBOSE if verbose else 0) | (_c.JOB_QUIET if quiet else 0) | \
        (_c.JOB_PROGRESS_SHOWN if progress_shown else 0)
    code = ctypes.c_int32(0)
    line = _read_string(_c.mf_job_batch_summary, _path(path), codes, len(listed), flags, ctypes.byref(code))
    return line, code.value


def failure_line(message: str, exit_code: int = EXIT_BAD_INPUT, prefix: str = "") -> str:
    """"motionfield: <prefix>error: ..." (or "internal error"): a failure the runner of a batch meets itself."""
    kind = "error" if exit_code == EXIT_BAD_INPUT else "internal error"
    return "motionfield: %s\n" % printable(prefix + kind + ": " + message)


_process_runners: dict = {}


def process_runner(settings: dict, load_model: bool) -> JobRunner:
    """The JobRunner of this process for `settings` (JobRunner's keyword
    arguments): what a worker keeps between jobs, so that it loads the model
    once; with `load_model`, the model is loaded before the first job (as the
    batch's own runner loaded it)."""
    key = tuple(sorted((k, tuple(v) if isinstance(v, (list, tuple)) else v) for k, v in settings.items()))
    runner = _process_runners.get(key)
    if runner is None:
        runner = _process_runners[key] = JobRunner(**settings)
        if load_model:
            runner.load_model()
    return runner


def run_line_in_process(settings: dict, load_model: bool, text: bytes, line: int, batch_path: str,
                        load_warnings: bool, threads: Optional[int] = None) -> JobResult:
    """JobRunner.run_line with this process's runner (process_runner) and
    intra-op threads: the task a batch runner's worker (a Dask worker) runs."""
    from . import get_num_threads, set_num_threads

    if threads is not None and get_num_threads() != threads:
        set_num_threads(threads)
    return process_runner(settings, load_model).run_line(text, line, batch_path, load_warnings)
