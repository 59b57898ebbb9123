"""What the headless add-on tests share: check() collects failures, log()
prints with the time since the start, finish() exits 1 after failures."""

import sys
import time

FAILURES = []
T0 = time.time()


def check(cond, what):
    if not cond:
        FAILURES.append(what)
        print("FAIL:", what)


def log(*a):
    print("[%5.1fs]" % (time.time() - T0), *a, flush=True)


def finish():
    log("done,", len(FAILURES), "failures")
    sys.exit(1 if FAILURES else 0)
