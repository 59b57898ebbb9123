"""The jobs of ``motionfield batch`` in Python: the JSON-lines job format, its
checks and messages, and one job run end to end through the package's API.

The job format lives only in the CLI (capi/cli: jsonl.cc, batch.cc, job.cc,
models.cc, cli.cc), not in the C ABI, so this module is a faithful port of it
for runners of the same files elsewhere (``python3 -m motionfield.dask``):
the same keys and type checks with the same messages, the same refusal of an
output an earlier line writes or that is the job's own input, the same model
choice (``--model`` or the default model, loaded only when the method needs
it), the same default methods and the same result lines ("motionfield: FILE
line N (id X): error: ...", the ``--json`` summary). What the C ABI checks
(method names, unit names, BVH and path files, ranges) is left to it.

One difference: a line that is not valid JSON is reported with Python's
description of the syntax error (the CLI quotes nlohmann-json's); both say
"invalid JSON: column N: ...". python/tests/dask_batch_test.py checks that the
rest matches the CLI.
"""

from __future__ import annotations

import dataclasses
import decimal
import json
import math
import os
import re
import stat
import threading
import time
from typing import Any, Dict, List, Optional, Tuple

import motionfield as mf

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2

#: Deepest nesting of a job line's JSON (the CLI's kJsonMaxDepth).
JSON_MAX_DEPTH = 64
#: The largest batch file read (the CLI's kMaxCliTextFileBytes).
MAX_BATCH_FILE_BYTES = 64 << 20

TASKS = ("inbetween", "fill", "resample", "renav")
_STDIO = "-"


class InputError(Exception):
    """Bad input found by the batch code itself (exit code 2); the message is for the user as is."""


@dataclasses.dataclass
class Settings:
    """The options of a batch run (the CLI's global options)."""

    threads: int = 1           # --threads: intra-op threads (the CLI's default for batch jobs: 1)
    verbose: bool = False
    quiet: bool = False
    json: bool = False
    model: str = ""            # --model PATH, "" for the default model
    twostage: Tuple[str, ...] = ()
    citl: Tuple[str, ...] = ()
    rig_map: str = ""          # --rig-map FILE
    units: str = ""            # --units, "" = auto
    preload_model: bool = False  # load the model before each worker's first job (see needs_model())

    def transformers(self) -> Tuple[str, ...]:
        """The transformer files added to the model, --twostage first."""
        return tuple(self.twostage) + tuple(self.citl)


@dataclasses.dataclass
class BatchJob:
    """One job of a batch line (the CLI's BatchJob)."""

    task: str = ""
    in_path: str = ""
    out_path: str = ""
    method: str = ""
    max_iterations: int = 0  # iteration budget of iterative methods; 0: each method's own
    id: str = ""
    has_keyframes: bool = False
    keyframes: List[int] = dataclasses.field(default_factory=list)
    has_gap: bool = False
    gap_begin: int = 0
    gap_end: int = 0
    fps: float = 0.0
    path_file: str = ""
    polyline: bool = False
    frames: int = 0
    rig_map: str = ""
    units: str = ""
    constraints_file: str = ""  # inbetween, fill: a constraints file
    constraints_json: str = ""  # ... or the same inline (JSON text)
    trajectory_file: str = ""  # inbetween, fill: a trajectory CSV, merged into the constraints
    alternatives: int = 0
    report_file: str = ""

    @property
    def constrained(self) -> bool:
        """Whether the job goes through solve() (constraints, alternatives or a report)."""
        return bool(self.constraints_file or self.constraints_json or self.trajectory_file or self.alternatives
                    or self.report_file)


@dataclasses.dataclass
class Failure:
    """A failure as the CLI reports it: exit code 2 for bad input, else 1."""

    exit_code: int
    message: str


@dataclasses.dataclass
class JobReport:
    """What a job did (the CLI's JobReport), and what the batch needs to print it."""

    method: str = ""
    model: str = ""
    frames_in: int = 0
    frames_out: int = 0
    read_ms: float = 0.0
    solve_ms: float = 0.0
    write_ms: float = 0.0
    warnings: str = ""
    verbose_line: str = ""     # the --verbose line of the job ("" without --verbose)
    constraints: str = ""      # the constraint report (JSON text), "" when not asked for
    alternatives: List[str] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class Outcome:
    """A job once run (or refused): its report, or why it failed.

    ``asked_load_warnings``: the job named no method and had a model, so the
    CLI would have given it the model's load warnings if it were the first
    such job of the batch; ``load_warnings`` holds them.
    """

    ok: bool = False
    report: Optional[JobReport] = None
    failure: Optional[Failure] = None
    asked_load_warnings: bool = False
    load_warnings: str = ""


@dataclasses.dataclass
class Entry:
    """One non-blank line of a batch file."""

    line: int
    label: str
    job: BatchJob
    failure: Optional[Failure] = None   # set when the line was refused before running

    @property
    def runnable(self) -> bool:
        """Whether the line parsed and its output was claimed."""
        return self.failure is None


# ------------------------------------------------------------------ failures and messages


def failure_of(error: BaseException) -> Failure:
    """The Failure of an exception, as the CLI's current_failure() makes it.

    Parameters
    ----------
    error : BaseException
        What a job raised.

    Returns
    -------
    Failure
        Exit code 2 for InputError and the library's invalid-argument, I/O,
        model and unsupported errors (the message as is); else 1 (library
        errors with their status name first).

    Raises
    ------
    None
    """
    if isinstance(error, InputError):
        return Failure(EXIT_BAD_INPUT, str(error))
    if isinstance(error, mf.Error):
        if isinstance(error, (mf.InvalidArgumentError, mf.FileError, mf.ModelError, mf.UnsupportedError)):
            return Failure(EXIT_BAD_INPUT, str(error))
        return Failure(EXIT_INTERNAL, "%s: %s" % (error.status_name, error))
    return Failure(EXIT_INTERNAL, str(error) or type(error).__name__)


def printable(text: str) -> str:
    """`text` safe to print (mf_printable_text), as the CLI prints every message."""
    try:
        return mf.printable_text(text)
    except Exception:  # out of memory: say so rather than print raw bytes
        return "(a message that could not be made printable)"


def failure_line(failure: Failure, prefix: str = "") -> str:
    """The stderr line of a failure: "motionfield: <prefix>error: ..." (or "internal error")."""
    kind = "error" if failure.exit_code == EXIT_BAD_INPUT else "internal error"
    return "motionfield: %s\n" % printable(prefix + kind + ": " + failure.message)


def warning_lines(warnings: str, prefix: str = "") -> str:
    """The stderr lines of warnings, one "motionfield: <prefix>warning: ..." per line."""
    return "".join("motionfield: %s\n" % printable(prefix + "warning: " + w) for w in getlines(warnings))


def getlines(text: str) -> List[str]:
    """The lines of `text` as std::getline reads them (no empty last line after a final newline)."""
    lines = text.split("\n")
    if lines[-1] == "":
        lines.pop()
    return lines


# ------------------------------------------------------------------ JSON


class JsonError(Exception):
    """A line is not valid JSON; the message starts with "column N: "."""

    def __init__(self, column: int, message: str) -> None:
        super().__init__("column %d: %s" % (column, message))
        self.column = column


class _Reject(Exception):
    def __init__(self, token: str, message: str) -> None:
        super().__init__(message)
        self.token = token


def _check_depth(text: str) -> None:
    depth, in_string, escaped = 0, False, False
    for i, c in enumerate(text):
        if in_string:
            if escaped:
                escaped = False
            elif c == "\\":
                escaped = True
            elif c == '"':
                in_string = False
        elif c == '"':
            in_string = True
        elif c in "[{":
            depth += 1
            if depth > JSON_MAX_DEPTH:
                raise JsonError(i + 1, "nesting deeper than %d levels" % JSON_MAX_DEPTH)
        elif c in "]}":
            depth -= 1


def _number(text: str, value: float) -> float:
    if math.isinf(value):
        raise _Reject(text, "number out of range: " + text)
    return value


def _parse_int(text: str) -> float:
    try:
        return _number(text, float(int(text)))
    except OverflowError:
        raise _Reject(text, "number out of range: " + text) from None


def _no_duplicates(pairs: List[Tuple[str, Any]]) -> Dict[str, Any]:
    out: Dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise _Reject(json.dumps(key, ensure_ascii=False), 'duplicate key "%s"' % key)
        out[key] = value
    return out


def _constant(name: str) -> Any:
    raise _Reject(name, "syntax error: %s is not JSON" % name)


def _has_lone_surrogate(value: Any) -> bool:
    if isinstance(value, str):
        return any("\ud800" <= c <= "\udfff" for c in value)
    if isinstance(value, list):
        return any(_has_lone_surrogate(v) for v in value)
    if isinstance(value, dict):
        return any(_has_lone_surrogate(k) or _has_lone_surrogate(v) for k, v in value.items())
    return False


def parse_json(line: bytes) -> Any:
    """Parses one line as strict JSON (RFC 8259), as the CLI's parse_json does.

    Parameters
    ----------
    line : bytes
        The line, UTF-8.

    Returns
    -------
    Any
        None, bool, float (every number), str, list or dict (in input order).

    Raises
    ------
    JsonError
        For invalid UTF-8, a syntax error, NaN or Infinity, a duplicate key, a
        number that overflows a double, a lone surrogate escape, or nesting
        deeper than JSON_MAX_DEPTH.
    """
    try:
        text = line.decode("utf-8")
    except UnicodeDecodeError as e:
        raise JsonError(len(line[:e.start].decode("utf-8")) + 1, "invalid UTF-8 byte") from None
    _check_depth(text)
    try:
        value = json.loads(text, object_pairs_hook=_no_duplicates, parse_int=_parse_int,
                           parse_float=lambda s: _number(s, float(s)), parse_constant=_constant)
    except json.JSONDecodeError as e:
        raise JsonError(e.colno, e.msg) from None
    except _Reject as e:
        at = text.find(e.token, text.find(e.token) + 1) if str(e).startswith("duplicate") else text.find(e.token)
        raise JsonError(max(at, 0) + 1, str(e)) from None
    if _has_lone_surrogate(value):
        at = re.search(r"\\u[dD][89a-fA-F]", text)
        raise JsonError(at.start() + 1 if at else 1, "invalid string: a lone surrogate escape")
    return value


def number_text(value: float) -> str:
    """A double as std::to_chars writes it: the shortest round-trip digits,
    fixed or scientific notation, whichever is shorter (fixed on a tie)."""
    if value == 0:
        return "-0" if math.copysign(1.0, value) < 0 else "0"
    sign = "-" if value < 0 else ""
    _, digit_tuple, exponent = decimal.Decimal(repr(abs(value))).as_tuple()
    digits = "".join(map(str, digit_tuple)).rstrip("0")
    exponent = int(exponent) + len(digit_tuple) - len(digits)
    n = len(digits)
    if exponent >= 0:
        fixed = digits + "0" * exponent
    elif -exponent < n:
        fixed = digits[:n + exponent] + "." + digits[n + exponent:]
    else:
        fixed = "0." + "0" * (-exponent - n) + digits
    e10 = exponent + n - 1
    scientific = digits[0] + ("." + digits[1:] if n > 1 else "") + "e" + ("+" if e10 >= 0 else "-") + \
        "%02d" % abs(e10)
    return sign + (fixed if len(fixed) <= len(scientific) else scientific)


def dump(value: Any) -> str:
    """Compact JSON text of a parsed value, as the CLI's JsonValue::dump()."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return number_text(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list):
        return "[" + ",".join(dump(v) for v in value) + "]"
    return "{" + ",".join(json.dumps(k, ensure_ascii=False) + ":" + dump(v) for k, v in value.items()) + "}"


def json_type_name(value: Any) -> str:
    """"null", "a boolean", "a number", "a string", "an array" or "an object"."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, float):
        return "a number"
    if isinstance(value, str):
        return "a string"
    return "an array" if isinstance(value, list) else "an object"


# ------------------------------------------------------------------ one line's job


def _where(key: str) -> str:
    return '"%s"' % key


def _required(obj: Dict[str, Any], key: str, task: str) -> Any:
    if key not in obj:
        raise InputError("missing key " + _where(key) + ("" if not task else ' (needed by task "%s")' % task))
    return obj[key]


def _string_value(v: Any, key: str, allow_empty: bool) -> str:
    if not isinstance(v, str):
        raise InputError(_where(key) + " must be a string, not " + json_type_name(v))
    if not allow_empty and not v:
        raise InputError(_where(key) + " must not be empty")
    if "\0" in v:
        raise InputError(_where(key) + " contains a NUL character (\\u0000), which no file name or value can hold")
    return v


def _int_value(v: Any, what: str) -> int:
    if not isinstance(v, float) or isinstance(v, bool):
        raise InputError(what + " must be an integer, not " + json_type_name(v))
    if v != math.floor(v) or v < -2**31 or v > 2**31 - 1:
        raise InputError(what + " must be an integer, not " + dump(v))
    return int(v)


def _int_array(v: Any, key: str) -> List[int]:
    if not isinstance(v, list):
        raise InputError(_where(key) + " must be an array of integers, not " + json_type_name(v))
    return [_int_value(item, "%s item %d" % (_where(key), i)) for i, item in enumerate(v)]


def _fps_value(v: Any) -> float:
    if not isinstance(v, float) or isinstance(v, bool):
        raise InputError('"fps" must be a number, not ' + json_type_name(v))
    return v


def _read_units(line: Dict[str, Any], job: BatchJob) -> None:
    if "units" not in line:
        return
    u = line["units"]
    if isinstance(u, float) and not isinstance(u, bool):
        if not u > 0:
            raise InputError('"units" must be positive, not ' + dump(u))
        job.units = dump(u)
    elif isinstance(u, str):
        job.units = _string_value(u, "units", False)
    else:
        raise InputError('"units" must be a unit name or a number, not ' + json_type_name(u))


def _read_constraints(line: Dict[str, Any], job: BatchJob) -> None:
    if "constraints" in line:
        c = line["constraints"]
        if isinstance(c, dict):
            job.constraints_json = dump(c)  # as the CLI's JsonValue::dump writes it (25, not 25.0)
        elif isinstance(c, str):
            job.constraints_file = _string_value(c, "constraints", False)
        else:
            raise InputError('"constraints" must be a file name or an object, not ' + json_type_name(c))
    if "trajectory" in line:
        job.trajectory_file = _string_value(line["trajectory"], "trajectory", False)
    if "alternatives" in line:
        job.alternatives = _int_value(line["alternatives"], '"alternatives"')
        if not 0 <= job.alternatives <= 16:
            raise InputError('"alternatives" must be between 0 and 16, not ' + dump(line["alternatives"]))
    if "report" in line:
        job.report_file = _string_value(line["report"], "report", False)


def _read_task_keys(line: Dict[str, Any], job: BatchJob) -> None:
    if job.task in ("inbetween", "fill"):
        _read_constraints(line, job)
    if job.task == "inbetween":
        job.keyframes = _int_array(_required(line, "keyframes", job.task), "keyframes")
        job.has_keyframes = True
    elif job.task == "fill":
        if "keyframes" in line:
            job.keyframes = _int_array(line["keyframes"], "keyframes")
            job.has_keyframes = True
        else:
            g = _required(line, "gap", job.task)
            if not isinstance(g, list) or len(g) != 2:
                raise InputError('"gap" must be an array of two integers [A, B], not ' +
                                 (dump(g) if isinstance(g, list) else json_type_name(g)))
            job.gap_begin = _int_value(g[0], '"gap" item 0')
            job.gap_end = _int_value(g[1], '"gap" item 1')
            job.has_gap = True
    elif job.task == "resample":
        job.fps = _fps_value(_required(line, "fps", job.task))
    else:  # renav
        if ("path" in line) == ("polyline" in line):
            raise InputError('task "renav" needs exactly one of "path" and "polyline"')
        job.polyline = "polyline" in line
        key = "polyline" if job.polyline else "path"
        job.path_file = _string_value(line[key], key, False)
        if "fps" in line:
            job.fps = _fps_value(line["fps"])
            if not job.fps > 0:
                raise InputError('"fps" must be positive, not ' + dump(line["fps"]))
        if "frames" in line:
            if not job.polyline:
                raise InputError('"frames" goes with "polyline" (a "path" has one point per frame)')
            job.frames = _int_value(line["frames"], '"frames"')


def batch_job_from_json(line: Any) -> BatchJob:
    """The job of one parsed line (the CLI's batch_job_from_json).

    Parameters
    ----------
    line : Any
        A value from parse_json().

    Returns
    -------
    BatchJob

    Raises
    ------
    InputError
        When the value is not an object, "task" is missing or unknown, or a key
        the task needs is missing or has the wrong type (the message names it).
    """
    if not isinstance(line, dict):
        raise InputError("a job must be a JSON object, not " + json_type_name(line))
    job = BatchJob()
    if "id" in line:
        job.id = line["id"] if isinstance(line["id"], str) else dump(line["id"])
    job.task = _string_value(_required(line, "task", ""), "task", False)
    if job.task not in TASKS:
        raise InputError('unknown task "%s" (expected "inbetween", "fill", "resample" or "renav")' % job.task)
    job.in_path = _string_value(_required(line, "in", job.task), "in", False)
    job.out_path = _string_value(_required(line, "out", job.task), "out", False)
    if "method" in line:
        job.method = _string_value(line["method"], "method", False)
    if "max_iterations" in line:
        job.max_iterations = _int_value(line["max_iterations"], '"max_iterations"')
        if not 0 <= job.max_iterations <= 100000:
            raise InputError('"max_iterations" must be between 0 and 100000, not ' + dump(line["max_iterations"]))
    if "rig_map" in line:
        job.rig_map = _string_value(line["rig_map"], "rig_map", False)
    _read_units(line, job)
    _read_task_keys(line, job)
    return job


# ------------------------------------------------------------------ the batch file


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


def read_lines(path: str) -> List[bytes]:
    """The lines of a batch file (std::getline's split; a UTF-8 BOM dropped)."""
    data = read_text_file(path, "batch file")
    if not data:
        return []
    lines = data.split(b"\n")
    if data.endswith(b"\n"):
        lines.pop()
    if lines[0].startswith(b"\xef\xbb\xbf"):
        lines[0] = lines[0][3:]
    return lines


def _blank(line: bytes) -> bool:
    return not line.strip(b" \t\r\n")


def parse_line(line: bytes, label: List[str]) -> BatchJob:
    """The job of one line; label[0] gains " (id X)" once the line parses."""
    try:
        value = parse_json(line)
    except JsonError as e:
        raise InputError("invalid JSON: %s" % e) from None
    if isinstance(value, dict) and "id" in value:
        label[0] += " (id %s)" % (value["id"] if isinstance(value["id"], str) else dump(value["id"]))
    job = batch_job_from_json(value)
    if job.in_path == _STDIO or job.out_path == _STDIO:
        raise InputError('"-" (standard input or output) is for single commands, not batch jobs')
    return job


def read_batch(path: str, settings: Optional["Settings"] = None) -> List[Entry]:
    """Every non-blank line of a batch file parsed and its files checked, in
    line order: against each other and every earlier line's (the CLI's
    check, mf_output_set_merge).

    Parameters
    ----------
    path : str
        The JSON-lines file.
    settings : Settings, optional
        The run's options (the command line's rig map is a job's input).

    Returns
    -------
    list of Entry
        One per non-blank line; a line that does not parse, writes what an
        earlier line writes or reads, or reads what it writes, carries its
        Failure.

    Raises
    ------
    InputError
        If the file cannot be read.
    """
    entries = []
    batch_files = mf.OutputSet()
    for i, raw in enumerate(read_lines(path)):
        if _blank(raw):
            continue
        label = ["%s line %d" % (path, i + 1)]
        entry = Entry(i + 1, "", BatchJob())
        try:
            entry.job = parse_line(raw, label)
            batch_files.merge(prepare_job(entry.job, settings or Settings()), "line %d" % (i + 1))
        except Exception as e:  # noqa: BLE001 (each failure is the line's)
            entry.failure = failure_of(e)
        entry.label = label[0]
        entries.append(entry)
    return entries


# ------------------------------------------------------------------ models


class Models:
    """The model of the jobs, chosen as the CLI's Models chooses it: --model
    PATH, else the default model, loaded on first need (a job naming no
    method, or one that needs the model); the transformers added to it."""

    def __init__(self, explicit_path: str, transformers: Tuple[str, ...]) -> None:
        self.explicit_path = explicit_path
        self.transformers = tuple(transformers)
        self.path = ""
        self.model: Optional[mf.Model] = None
        self._tried_default = False
        self._default_error = ""
        self._lock = threading.Lock()

    def load_explicit(self) -> None:
        """Loads --model, if given (the library's error if it does not load)."""
        if self.explicit_path and self.model is None:
            self._use(mf.Model(self.explicit_path), self.explicit_path)

    def for_method(self, method: str) -> Optional[mf.Model]:
        """The model for a job with `method` ("" = the default method); None when
        the method needs none and no --model was given."""
        with self._lock:
            if self.explicit_path:
                self.load_explicit()
                return self.model
            needs = bool(method) and mf.find_method(method).needs_model
            if method and not needs:
                return self.model
            self._load_default()
            if needs and self.model is None:
                raise InputError("method '%s' needs the prior, and no model is loaded (name one with --model)"
                                 % method)
            return self.model

    def preload(self) -> None:
        """Loads the model before the first job, as ``motionfield batch --jobs N``
        does when a job needs it (jobs that need none then report it too); a
        failure is remembered and reported by the jobs that need the model."""
        try:
            self.for_method("")
        except Exception:  # noqa: BLE001 (reported by the jobs that need it)
            pass

    def load_warnings(self) -> str:
        """The transformer files next to the model that were there but did not
        load, one warning per line (the CLI's Models::load_warnings_of)."""
        if self.model is None:
            return ""
        out = ""
        for kind in self.model.describe()["inbetweeners"].values():
            if kind["error"]:
                out += (kind["file"] + " next to the model did not load, so the methods that need it cannot run "
                        "and the default method does without it: " + kind["error"] + "\n")
        return out

    def _load_default(self) -> None:
        if self._tried_default:
            if self._default_error:
                raise InputError(self._default_error)
            return
        self._tried_default = True
        path = mf.default_model_path()
        if path is None:
            return
        try:
            model = mf.Model(path)
        except mf.Error as e:
            self._default_error = "cannot load the default model: %s" % e
            raise InputError(self._default_error) from None
        self._use(model, path)

    def _use(self, model: mf.Model, path: str) -> None:
        for file in self.transformers:
            model = model.with_inbetweener(file)
        self.model = model
        self.path = path


_process_models: Dict[Tuple[str, Tuple[str, ...]], Models] = {}
_process_models_lock = threading.Lock()


def process_models(settings: Settings) -> Models:
    """The Models of this process for `settings` (one per model path and
    transformers): what a worker keeps between jobs, so that each worker
    process loads the model once."""
    key = (settings.model, settings.transformers())
    with _process_models_lock:
        if key not in _process_models:
            _process_models[key] = Models(settings.model, settings.transformers())
        return _process_models[key]


# ------------------------------------------------------------------ one job end to end

_FROM_CHARS_NUMBER = re.compile(r"-?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|inf(?:inity)?|nan(?:\([A-Za-z0-9_]*\))?)",
                                re.IGNORECASE)


def units_scale(units: str, what: str) -> Optional[float]:
    """Metres per file unit of --units or a job's "units" (the CLI's
    units_scale): None for "" or "auto" (detected), a positive number, or a
    unit name."""
    if not units or units == "auto":
        return None
    if _FROM_CHARS_NUMBER.fullmatch(units):
        v = float("nan") if "nan" in units.lower() else float(units)
        if not (math.isfinite(v) and v > 0):
            raise InputError("%s must be positive, not %s" % (what, units))
        return v
    try:
        return mf.length_unit_scale(units)
    except mf.Error as e:
        raise InputError("%s: %s; auto (the default) detects it" % (what, e)) from None


class _FilePath(os.PathLike):  # type: ignore[type-arg]
    """A file name given to rig_map= as a file (never read as JSON text)."""

    def __init__(self, path: str) -> None:
        self._path = path

    def __fspath__(self) -> str:
        return self._path


def prepare_job(job: BatchJob, settings: "Settings") -> mf.OutputSet:
    """What a job checks before reading anything (the CLI's prepare_job): its
    method exists, re-navigation's numbers, and its files (mf_output_set):
    no two outputs, and no output and input, are one file.

    Parameters
    ----------
    job : BatchJob
        The job.
    settings : Settings
        The run's options.

    Returns
    -------
    motionfield.OutputSet
        The job's files, its outputs to be staged and committed.

    Raises
    ------
    InputError, motionfield.Error
        On the first problem.
    """
    renav = job.task == "renav"
    if job.method and not renav:
        mf.find_method(job.method)
    if renav:
        if job.fps < 0 or not math.isfinite(job.fps):
            raise InputError("renav: the fps must be positive")
        if job.polyline and job.frames != 0 and job.frames < 2:
            raise InputError("renav: the frame count must be at least 2")
    if job.out_path == _STDIO and job.alternatives > 0:
        raise InputError("--alternatives writes OUT_1.bvh .. beside the output: name an output file, not -")
    files = mf.OutputSet()
    if job.in_path != _STDIO:
        files.add_input(job.in_path, "input")
    files.add_input(job.path_file, "path file")
    files.add_input(job.rig_map or settings.rig_map, "rig map file")
    files.add_input(job.constraints_file, "constraints file")
    files.add_input(job.trajectory_file, "trajectory file")
    if job.out_path != _STDIO:
        files.add_output(job.out_path, "output")
    for i in range(1, job.alternatives + 1):
        files.add_output(alternative_path(job.out_path, i), "alternative")
    if job.report_file:
        files.add_output(job.report_file, "report")
    return files


def _solve_constrained(job: BatchJob, options: Dict[str, Any], motion: mf.Motion) -> "mf.Solution":
    """The CLI's constrained path: the job's constraints plus its known frames as whole-pose keys."""
    constraints = (mf.Constraints.load(job.constraints_file) if job.constraints_file
                   else mf.Constraints(job.constraints_json) if job.constraints_json else mf.Constraints())
    if job.trajectory_file:
        constraints.load_trajectory(job.trajectory_file)
    if job.task == "inbetween" or job.has_keyframes:
        keys = job.keyframes
    else:
        n = motion.frame_count
        if not 1 <= job.gap_begin < job.gap_end <= n - 1:
            raise InputError("gap %d:%d must satisfy 1 <= A < B <= frames - 1 (the input has %d frames)" %
                             (job.gap_begin, job.gap_end, n))
        keys = [f for f in range(n) if f < job.gap_begin or f >= job.gap_end]
    constraints.add_keys(keys)
    return mf.solve(motion, constraints=constraints, alternatives=job.alternatives, **options)


def _solve(job: BatchJob, settings: Settings, model: Optional[mf.Model], motion: mf.Motion) -> Any:
    rig_map = job.rig_map or settings.rig_map
    options: Dict[str, Any] = dict(method=job.method or None, model=model,
                                   rig_map=_FilePath(rig_map) if rig_map else None,
                                   max_iterations=job.max_iterations)
    if job.constrained:
        return _solve_constrained(job, options, motion)
    if job.task == "inbetween" or (job.task == "fill" and job.has_keyframes):
        return mf.inbetween(motion, job.keyframes, **options)
    if job.task == "fill":
        return mf.fill(motion, job.gap_begin, job.gap_end, **options)
    if job.task == "resample":
        return mf.resample(motion, job.fps, **options)
    path = mf.load_path_csv(job.path_file)
    return mf.renav(motion, path, polyline=job.polyline, frames=job.frames if job.polyline else 0, fps=job.fps,
                    **options)


def _method_name(job: BatchJob, model: Optional[mf.Model]) -> str:
    if job.method:
        return job.method
    if job.task == "resample":
        return "prior" if model is not None else "cubic"
    if job.task == "renav":
        return "nemf"
    return mf.default_method(model=model)


def alternative_path(out: str, index: int) -> str:
    """Where alternative `index` (1..) of output `out` goes: OUT_1.bvh for OUT.bvh (the CLI's)."""
    stem, ext = os.path.splitext(os.path.basename(out))
    return os.path.join(os.path.dirname(out), "%s_%d%s" % (stem, index, ext))


def run_job(job: BatchJob, settings: Settings, models: Models) -> Outcome:
    """Runs one job end to end (the CLI's run_job): check, read, solve, write.

    Parameters
    ----------
    job : BatchJob
        The job.
    settings : Settings
        The run's options.
    models : Models
        The model cache of this process.

    Returns
    -------
    Outcome
        Its report, or its Failure (never raises for a job's own failure).

    Raises
    ------
    None
    """
    outcome = Outcome()
    try:
        t0 = time.perf_counter()
        files = prepare_job(job, settings)
        model = models.for_method("nemf" if job.task == "renav" and not job.method else job.method)
        if not job.method and model is not None:
            outcome.asked_load_warnings = True
            outcome.load_warnings = models.load_warnings()
        motion = mf.Motion.load_bvh(job.in_path, units=units_scale(job.units or settings.units,
                                                                    '"units"' if job.units else "--units (--length-scale)"))
        t1 = time.perf_counter()
        solved = _solve(job, settings, model, motion)
        result = solved.motion if isinstance(solved, mf.Solution) else solved
        t2 = time.perf_counter()
        # Every output staged, then all put in place at once: a failure leaves none behind.
        files.write_motion(job.out_path, result)
        alternatives: List[str] = []
        if isinstance(solved, mf.Solution):
            for i, m in enumerate(solved.motions[1:], 1):
                alternatives.append(alternative_path(job.out_path, i))
                files.write_motion(alternatives[-1], m)
            if job.report_file:
                files.write(job.report_file, solved.report_json + "\n")
        files.commit()
        t3 = time.perf_counter()
        ran = solved.method if isinstance(solved, mf.Solution) and solved.method else _method_name(job, model)
        r = JobReport(method=ran, model=models.path if model is not None else "",
                      frames_in=motion.frame_count, frames_out=result.frame_count, read_ms=(t1 - t0) * 1e3,
                      solve_ms=(t2 - t1) * 1e3, write_ms=(t3 - t2) * 1e3, warnings=result.warnings,
                      constraints=solved.report_json if isinstance(solved, mf.Solution) else "",
                      alternatives=alternatives)
        if settings.verbose:
            r.verbose_line = "motionfield: %s\n" % printable(
                "%s %s -> %s, model %s: %d -> %d frames, method %s, %d threads; read %.1f ms, solve %.1f ms, "
                "write %.1f ms" % (job.task, job.in_path, job.out_path, r.model or "none", r.frames_in,
                                   r.frames_out, r.method, settings.threads, r.read_ms, r.solve_ms, r.write_ms))
        outcome.ok, outcome.report = True, r
    except Exception as e:  # noqa: BLE001 (each failure is the job's)
        outcome.failure = failure_of(e)
    return outcome


def run_job_in_process(job: BatchJob, settings: Settings) -> Outcome:
    """run_job() with this process's model cache and intra-op threads: the
    task a batch runner (a Dask worker) runs.

    Parameters
    ----------
    job : BatchJob
        The job.
    settings : Settings
        The run's options (``threads`` sets this process's intra-op threads).

    Returns
    -------
    Outcome

    Raises
    ------
    None
    """
    if mf.get_num_threads() != settings.threads:
        mf.set_num_threads(settings.threads)
    models = process_models(settings)
    if settings.preload_model:
        models.preload()
    return run_job(job, settings, models)


def needs_model(job: BatchJob) -> bool:
    """Whether a job loads the model (it names no method, or one that needs the
    model; re-navigation always): with --model, or when a job of the batch
    needs it, ``motionfield batch --jobs N`` loads the model before running
    any job, and every job's summary then names it."""
    method = "nemf" if job.task == "renav" and not job.method else job.method
    if not method:
        return True
    try:
        return mf.find_method(method).needs_model
    except mf.Error:
        return False  # the job fails on its unknown method


def job_json(job: BatchJob, report: Optional[JobReport], failure: Optional[Failure], line: int = 0) -> str:
    """The --json summary of one job, as the CLI prints it (one line, no spaces)."""
    j: Dict[str, Any] = {}
    if line > 0:
        j["line"] = line
    if job.id:
        j["id"] = job.id
    j.update(task=job.task, **{"in": job.in_path, "out": job.out_path})
    if failure is not None:
        j.update(status="error", exit_code=failure.exit_code, error=failure.message)
    elif report is not None:
        j.update(status="ok", method=report.method, model=report.model, frames_in=report.frames_in,
                 frames_out=report.frames_out,
                 timings_ms={"read": report.read_ms, "solve": report.solve_ms, "write": report.write_ms,
                             "total": report.read_ms + report.solve_ms + report.write_ms},
                 warnings=getlines(report.warnings))
        if report.constraints:
            j.update(alternatives=report.alternatives, constraints=json.loads(report.constraints))
    return json.dumps(j, ensure_ascii=False, separators=(",", ":"))


def outcome_text(entry: Entry, outcome: Outcome, settings: Settings) -> Tuple[str, str]:
    """(stderr, stdout) text of a finished line, as the CLI's batch prints it:
    the --verbose line, the warnings or the failure, and the --json line."""
    err, out = "", ""
    if outcome.ok and outcome.report is not None:
        err += outcome.report.verbose_line
        if not settings.quiet:
            err += warning_lines(outcome.report.warnings, entry.label + ": ")
        if settings.json:
            out = job_json(entry.job, outcome.report, None, entry.line) + "\n"
    else:
        failure = outcome.failure or Failure(EXIT_INTERNAL, "the job did not run")
        err += failure_line(failure, entry.label + ": ")
        if settings.json:
            out = job_json(entry.job, None, Failure(failure.exit_code, printable(failure.message)), entry.line) + "\n"
    return err, out


def summary(path: str, outcomes: List[Outcome], settings: Settings, progress_shown: bool) -> Tuple[str, int]:
    """The batch's last stderr line (when the CLI prints it) and its exit code."""
    bad = sum(1 for o in outcomes if not o.ok and o.failure is not None and o.failure.exit_code == EXIT_BAD_INPUT)
    internal = sum(1 for o in outcomes if not o.ok) - bad
    failed, total = bad + internal, len(outcomes)
    line = ""
    if failed > 0 or settings.verbose or (progress_shown and not settings.quiet):
        line = "motionfield: %s\n" % printable("batch %s: %d jobs, %d ok, %d failed" % (path, total, total - failed,
                                                                                       failed))
    return line, (EXIT_INTERNAL if internal else EXIT_BAD_INPUT if bad else EXIT_OK)
