#!/usr/bin/env python3
"""Lists C and C++ functions longer than a limit in the library folders.

    usage: scripts/check-function-length.py [--max N] [--all] [PATH ...]

PATH are folders or files relative to the repository root (default: capi/src,
tasks and prior).
A function's length runs from the first line of its signature to its closing
brace, both included. Prints one row per function over the limit (or, with
--all, every function), longest first: `LINES FILE:LINE NAME`. Exits 1 when a
function is over the limit, else 0.

A heuristic, not a parser: comments, string and character literals are blanked,
then braces are matched. A brace block opened at namespace or class level
whose header (the text since the previous `;`, `{` or `}`) holds a `(` and no
namespace/class/struct/union/enum keyword is a function; everything nested in
it (lambdas, local classes) counts toward it. Braced initialisers at namespace
level (`x = {...}`) are skipped.
"""
import argparse
import os
import re
import signal
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_PATHS = ["capi/src", "tasks", "prior"]
EXCLUDED = []
SUFFIXES = (".cc", ".cpp", ".cxx", ".h", ".hpp")
CONTAINER = re.compile(r"\b(namespace|class|struct|union|enum)\b|^\s*extern\s*$")


def blank_comments_and_literals(text):
    """The text with comments, string and character literals replaced by spaces
    (newlines kept, so line numbers stay)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == 'R' and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            open_paren = text.find("(", i + 2)
            delimiter = text[i + 2:open_paren]
            j = text.find(")" + delimiter + '"', open_paren)
            j = n if j < 0 else j + len(delimiter) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # a digit separator: 1'000'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(" " * (j - i))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """(first line, last line, name) of every function defined in the file."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = blank_comments_and_literals(f.read())
    # Preprocessor lines (with their continuations) are not code.
    text = re.sub(r"(?m)^[ \t]*#.*(\\\n.*)*$", lambda m: re.sub(r"[^\n]", " ", m.group(0)), text)
    line_at, line = [], 1
    for c in text:
        line_at.append(line)
        line += c == "\n"
    found = []
    function = None  # (first line, name, depth inside it) of the function being read
    header_start = 0
    i = 0
    while i < len(text):
        c = text[i]
        if c not in "{};":
            i += 1
            continue
        if function:
            first, name, inner = function
            inner += {"{": 1, "}": -1}.get(c, 0)
            function = (first, name, inner)
            if inner == 0:
                found.append((first, line_at[i], name))
                function = None
        elif c == "{":
            header = text[header_start:i]
            stripped = header.strip()
            before_paren = stripped.split("(")[0]
            if CONTAINER.search(before_paren) or stripped in ("extern", ""):
                pass  # a namespace or class body: its functions are found inside
            elif "(" in stripped and not re.search(r"=\s*$", stripped):
                first_char = header_start + len(header) - len(header.lstrip())
                words = before_paren.split()
                function = (line_at[first_char], words[-1] if words else "?", 1)
            else:  # a braced initialiser: skip to its matching brace
                level = 0
                while i < len(text):
                    level += {"{": 1, "}": -1}.get(text[i], 0)
                    if level == 0:
                        break
                    i += 1
        header_start = i + 1
        i += 1
    return found


def files(paths):
    for p in paths:
        full = os.path.join(ROOT, p)
        if os.path.isfile(full):
            yield p
            continue
        for directory, subdirs, names in os.walk(full):
            rel_dir = os.path.relpath(directory, ROOT)
            subdirs[:] = sorted(d for d in subdirs if os.path.join(rel_dir, d) not in EXCLUDED)
            for name in sorted(names):
                if name.endswith(SUFFIXES):
                    yield os.path.join(rel_dir, name)


def main():
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # quiet under `| head`
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--max", type=int, default=60, help="longest allowed function, in lines (default 60)")
    parser.add_argument("--all", action="store_true", help="list every function, not only the long ones")
    parser.add_argument("paths", nargs="*", default=DEFAULT_PATHS)
    args = parser.parse_args()
    rows = []
    for rel in files(args.paths):
        for first, last, name in functions(os.path.join(ROOT, rel)):
            rows.append((last - first + 1, rel, first, name))
    rows.sort(key=lambda r: (-r[0], r[1], r[2]))
    over = [r for r in rows if r[0] > args.max]
    for length, rel, first, name in rows if args.all else over:
        print(f"{length:5d} {rel}:{first} {name}")
    if over:
        print(f"{len(over)} function(s) over {args.max} lines", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
