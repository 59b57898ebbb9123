#!/usr/bin/python3
"""Chooses the thresholds of the latent solvers' fallback to interpolation (tasks/latent/fallback.h).

Reads per-window CSVs of `motionfield-bench --windows-csv ... --no-fallback` with the methods
interp and nemf-detail on the same windows (Bandai Namco and foreign capture, training splits),
and tries every rule "interpolation when the final data terms d > C, or d > A and d > B per cm of
key motion" of a small grid. For each rule it prints the worst foreign group's ratio of L2P to
interpolation's (over every task row), the largest loss of any Bandai row's ratio, and whether the
hand-made sample walk (samples/walk_keyframes.bvh: d = 0.10 at 64.5 cm with keys every 20 frames,
0.083 at 52.2 cm every 15, from the warnings of `motionfield inbetween`) keeps the learned result.

Usage: scripts/fallback-thresholds.py BANDAI.csv FOREIGN.csv [--max-bandai-loss 0.01]
"""
import argparse
import csv
from collections import defaultdict

import numpy as np

DATA_TERMS = ("rotation", "root_orientation", "position", "root_translation")
SAMPLE_WALK = ((0.10, 64.5), (0.083, 52.2), (0.122, 95.0), (0.127, 81.0))


def load(paths):
    """{(row, group): array of (d, key motion cm, L2P nemf-detail, L2P interp)}"""
    windows = defaultdict(dict)
    for path in paths:
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                key = (r["dataset"], r["content"] or r["rig"], r["clip"], r["task"], r["row"], r["start"])
                windows[key][r["method"]] = r
    rows = defaultdict(list)
    for key, methods in windows.items():
        if not {"interp", "nemf-detail"} <= set(methods):
            continue
        n, i = methods["nemf-detail"], methods["interp"]
        d = sum(float(n.get("final." + t) or 0.0) for t in DATA_TERMS)
        rows[(key[3] + " " + key[4], key[0] + ": " + key[1])].append(
            (d, float(n["key_motion_cm"]), float(n["l2p"]), float(i["l2p"])))
    return {k: np.array(v) for k, v in rows.items()}


def falls_back(d, km, a, b, c):
    return (d > c) | ((d > a) & (d > b * km))


def evaluate(rows, a, b, c):
    worst, loss, ratios = 0.0, 0.0, {}
    for key, x in rows.items():
        d, km, learned, interp = x.T
        ratio = np.where(falls_back(d, km, a, b, c), interp, learned).sum() / interp.sum()
        ratios[key] = (learned.sum() / interp.sum(), ratio, falls_back(d, km, a, b, c).mean())
        if key[1].startswith("bandai"):
            loss = max(loss, ratio - learned.sum() / interp.sum())
        else:
            worst = max(worst, ratio)
    return worst, loss, ratios


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("csv", nargs="+")
    p.add_argument("--max-bandai-loss", type=float, default=0.01)
    args = p.parse_args()
    rows = load(args.csv)
    results = []
    for a in (0.035, 0.05, 0.07):
        for b in (0.002, 0.003, 0.004, 0.006, 0.008, 0.01, 0.015):
            for c in (0.12, 0.15, 0.2, 0.25, 0.3, np.inf):
                worst, loss, _ = evaluate(rows, a, b, c)
                sample = not any(falls_back(d, km, a, b, c) for d, km in SAMPLE_WALK)
                results.append((worst, loss, a, b, c, sample))
    ok = sorted(r for r in results if r[1] <= args.max_bandai_loss and r[5])
    print("rules that keep the sample walk and lose at most %.3f on any Bandai row, best first:" % args.max_bandai_loss)
    print("worst foreign group | largest Bandai loss | A | B (per cm) | C")
    for r in ok[:8]:
        print("%.3f | %.3f | %g | %g | %g" % r[:5])
    if ok:
        _, _, a, b, c, _ = ok[0]
        print("\nthe best rule per row and group: ratio without -> with the fallback (share falling back)")
        for key, (before, after, share) in sorted(evaluate(rows, a, b, c)[2].items()):
            print("%-12s %-28s %.3f -> %.3f (%3.0f %%)" % (key[0], key[1], before, after, 100 * share))


if __name__ == "__main__":
    main()
