"""A library of clips on Dask: the jobs of ``motionfield batch`` on a cluster.

Usage::

    python3 -m motionfield.dask JOBS.jsonl [--workers N | --scheduler ADDRESS]
        [--threads N] [--model PATH] [--twostage PATH] [--citl PATH]
        [--rig-map FILE] [--units U] [--json] [--quiet] [--verbose]

Reads the same JSON-lines jobs as ``motionfield batch JOBS.jsonl`` (one job
per line, the same keys, checks and messages: the library's job runner,
motionfield.jobs) and runs them
on a ``distributed.Client``: a LocalCluster of N worker processes (one thread
each) on this machine by default, or the scheduler at ADDRESS (its workers need
this package and the library, and see the same file system). Each worker
process loads the model once and keeps it for every job it runs; each job
writes its output atomically (the library writes a temporary file in the
output's directory and renames it). The outputs are those of ``motionfield
batch`` with the same ``--threads`` (the intra-op threads of each worker
process, 2 by default as for the CLI), bit for bit. Messages are the CLI's:
a failed job is reported on stderr with its line and id (the others still
run), ``--json`` prints one summary per job on stdout, in line order; the exit
code is 0 when every job succeeded, 1 when one hit an internal error, else 2.
On a terminal, a progress line on stderr counts the finished jobs.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
import time
import uuid
from typing import Dict, Optional, Sequence

from . import jobs as mfj


def _arguments(argv: Optional[Sequence[str]]) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="python3 -m motionfield.dask",
        description="Runs the jobs of a `motionfield batch` file (JSON lines) on Dask: a local cluster of "
                    "worker processes, or an existing scheduler.")
    p.add_argument("jobs", metavar="JOBS.jsonl", help="the jobs, one JSON object per line")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=2, metavar="N",
                       help="worker processes of the local cluster, one thread each (default 2)")
    where.add_argument("--scheduler", type=_non_empty, metavar="ADDRESS",
                       help="an existing Dask scheduler, e.g. tcp://host:8786")
    p.add_argument("--threads", type=int, default=1, metavar="N",
                   help="intra-op threads of each worker process (default 1, as for the CLI's batch jobs)")
    p.add_argument("--model", type=_non_empty, metavar="PATH",
                   help="the prior's model file (default: the default model)")
    p.add_argument("--twostage", action="append", default=[], type=_non_empty, metavar="PATH",
                   help="a two-stage transformer file (repeatable)")
    p.add_argument("--citl", action="append", default=[], type=_non_empty, metavar="PATH",
                   help="a CITL transformer file (repeatable)")
    p.add_argument("--rig-map", type=_non_empty, metavar="FILE", help="a JSON rig map for every job without its own")
    p.add_argument("--units", "--length-scale", default="", metavar="U",
                   help="the BVH length unit of every job without its own (default auto)")
    p.add_argument("--json", action="store_true", help="a JSON summary of each job on stdout, in line order")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress line and no warnings")
    p.add_argument("-v", "--verbose", action="store_true", help="what each job ran and how long it took (stderr)")
    args = p.parse_args(argv)
    if not 1 <= args.workers <= 256:
        p.error("--workers must be 1 to 256")
    if not 1 <= args.threads <= 1024:
        p.error("--threads must be 1 to 1024")
    return args


def _non_empty(value: str) -> str:
    """An option's value; an empty one (--model "") would silently mean the default: refused, as by the CLI."""
    if not value:
        raise argparse.ArgumentTypeError("needs a value")
    return value


class _ProgressLine:
    """"[done/total] jobs" on stderr, redrawn as jobs finish (a terminal only)."""

    def __init__(self, enabled: bool, total: int) -> None:
        self.enabled, self.total, self.start = enabled, total, time.monotonic()
        self.drawn = False

    def draw(self, done: int, failed: int) -> None:
        if not self.enabled:
            return
        width = 30
        filled = width * done // max(self.total, 1)
        sys.stderr.write("\r\033[K[%s%s] %d/%d jobs, %d failed, %.0f s" % (
            "#" * filled, "." * (width - filled), done, self.total, failed, time.monotonic() - self.start))
        sys.stderr.flush()
        self.drawn = True

    def clear(self) -> None:
        if self.drawn:
            sys.stderr.write("\r\033[K")
            sys.stderr.flush()
            self.drawn = False


def _distributed():  # type: ignore[no-untyped-def]
    try:
        import distributed
    except ImportError as e:
        raise mfj.InputError("python3 -m motionfield.dask needs Dask's distributed package (Debian: "
                             "python3-distributed; `make deps` installs it): %s" % e) from None
    return distributed


def _client(args: argparse.Namespace):  # type: ignore[no-untyped-def]
    distributed = _distributed()

    if args.scheduler:
        return distributed.Client(args.scheduler), None
    # CRITICAL, not ERROR: a worker process of our own cluster may log "Scheduler was unaware of this
    # worker" while the cluster closes; that is not the user's business, and a job's failure comes back
    # through its future. Likewise the worker's warning that its scratch directory took over a second
    # on a loaded machine (a Python warning in the spawned process, so it goes through the environment).
    scratch = "ignore:Creating scratch directories"
    os.environ["PYTHONWARNINGS"] = ",".join(w for w in (os.environ.get("PYTHONWARNINGS"), scratch) if w)
    cluster = distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.CRITICAL, memory_limit=0)
    return distributed.Client(cluster), cluster


class _Printer:
    """Prints each line's messages in line order, as soon as every earlier line has finished."""

    def __init__(self, total: int, json_lines: bool, progress: _ProgressLine) -> None:
        self.total, self.json_lines, self.progress = total, json_lines, progress
        self.results: Dict[int, mfj.JobResult] = {}
        self.printed = 0

    def finish(self, k: int, result: mfj.JobResult) -> None:
        self.results[k] = result
        self.progress.clear()
        while self.printed < self.total and self.printed in self.results:
            r = self.results[self.printed]
            sys.stderr.flush()
            sys.stderr.buffer.write(r.messages)
            sys.stderr.flush()
            if self.json_lines:
                sys.stdout.flush()
                sys.stdout.buffer.write(r.json + b"\n")
                sys.stdout.flush()
            self.printed += 1
        self.progress.draw(len(self.results), sum(1 for x in self.results.values() if x.exit_code != 0))


def _worker_failure(batch_path: str, line: int, err: BaseException) -> mfj.JobResult:
    """The result of a job whose worker died: an internal error of its line."""
    message = "the Dask worker running the job failed: %s" % (str(err) or type(err).__name__)
    text = mfj.failure_line(message, mfj.EXIT_INTERNAL, "%s line %d: " % (batch_path, line))
    summary = {"line": line, "status": "error", "exit_code": mfj.EXIT_INTERNAL, "error": mfj.printable(message)}
    return mfj.JobResult(mfj.EXIT_INTERNAL, text.encode("utf-8"),
                         json.dumps(summary, ensure_ascii=False, separators=(",", ":")).encode("utf-8"))


def _run(args: argparse.Namespace, settings: dict) -> int:
    lines = mfj.read_lines(args.jobs)
    # Every line checked here first, in line order (as `motionfield batch --jobs N` does), the model a job
    # needs loaded once; the workers then run the lines on their own runners.
    runner = mfj.JobRunner(preload_model=True, **settings)
    checked = [runner.check_line(text, n, args.jobs) for n, text in lines]
    load_model = bool(runner.model_path)
    progress = _ProgressLine(sys.stderr.isatty() and not settings["quiet"], len(lines))
    printer = _Printer(len(lines), args.json, progress)
    runnable = [k for k, job in enumerate(checked) if job.runnable]
    if runnable:
        distributed = _distributed()
        progress.draw(0, 0)
        client, cluster = _client(args)
        try:
            run = uuid.uuid4().hex[:12]  # task keys unique to this run: a shared scheduler merges equal keys
            futures = {client.submit(mfj.run_line_in_process, settings, load_model, lines[k][1], lines[k][0],
                                     args.jobs, checked[k].has_load_warnings, settings["threads"], pure=False,
                                     key="motionfield-%s-line-%d" % (run, lines[k][0])): k for k in runnable}
            for k, job in enumerate(checked):
                if not job.runnable:
                    printer.finish(k, runner.run(job))
            for future in distributed.as_completed(futures):
                k = futures[future]
                try:
                    result = future.result()
                except Exception as err:  # noqa: BLE001 (a worker died: the job failed, the others go on)
                    result = _worker_failure(args.jobs, lines[k][0], err)
                printer.finish(k, result)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    else:
        for k, job in enumerate(checked):
            printer.finish(k, runner.run(job))
    progress.clear()
    line, code = mfj.summary(args.jobs, [printer.results[k].exit_code for k in range(len(lines))],
                             settings["verbose"], settings["quiet"], progress.enabled)
    sys.stderr.write(line)
    return code


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Runs a batch file on Dask (see the module's documentation).

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default: sys.argv[1:]).

    Returns
    -------
    int
        The exit code: 0 every job succeeded, 1 an internal error, 2 bad input.

    Raises
    ------
    SystemExit
        For bad arguments (argparse, exit code 2).
    """
    args = _arguments(argv)
    settings = dict(threads=args.threads, model=args.model or "", inbetweeners=list(args.twostage) + list(args.citl),
                    rig_map=args.rig_map or "", units=args.units, verbose=args.verbose, quiet=args.quiet)
    try:
        import motionfield as mf

        mf.set_num_threads(args.threads)
        if args.verbose:
            sys.stderr.write("motionfield: %d intra-op threads\n" % args.threads)
        return _run(args, settings)
    except mfj.InputError as e:
        sys.stderr.write(mfj.failure_line(str(e)))
        return mfj.EXIT_BAD_INPUT
    except Exception as e:  # noqa: BLE001 (the CLI's top-level handler: a message and an exit code)
        bad = isinstance(e, (mf.InvalidArgumentError, mf.FileError, mf.ModelError, mf.UnsupportedError))
        code = mfj.EXIT_BAD_INPUT if bad else mfj.EXIT_INTERNAL
        message = str(e) if bad or not isinstance(e, mf.Error) else "%s: %s" % (e.status_name, e)
        sys.stderr.write(mfj.failure_line(message or type(e).__name__, code))
        return code


if __name__ == "__main__":
    os.environ.setdefault("PYTHONDONTWRITEBYTECODE", "1")
    sys.exit(main())
