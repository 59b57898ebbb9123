#!/usr/bin/python3
"""Which run-time signal tells that the learned method does worse than interpolation on a window?

Reads the per-window CSVs of `motionfield-bench --windows-csv` (bench/window_log.h) with the
methods interp, detail and nemf-detail on the same windows, and prints, per task row and per
group of windows (dataset / content), for every candidate signal:

* AUC (over all windows, and per group): how well the signal ranks the windows where
  nemf-detail's L2P exceeds interpolation's above the others (0.5: chance; higher: a larger
  signal means "worse than interp");
* the pooled L2P ratio to interpolation of nemf-detail, of the best per-window choice (an
  oracle), and of the fallback "interpolation when the signal is above t" with t chosen on
  the tuning windows (below), and the fraction of windows that fall back;
* the same for a soft blend toward interpolation with weight w = clip((s - t0) / (t1 - t0), 0, 1),
  scored with the bound L2P(blend) <= (1 - w) L2P(nemf-detail) + w L2P(interp) (the blend of
  joint positions; the norm is convex), so the blend's number is an upper bound.

Only signals a method has at run time are used (never the truth of the unknown frames):
energy terms of the solver before and after its minimisation, the distance of the detail
transformer's start and of the solution to interpolation, and how far the keys move.

Thresholds minimise the worst group's fallback ratio, then the mean over groups, on the windows of
--tune-csv (those windows are then left out of the evaluation), or in-sample without it.

Usage: scripts/never-worse-signals.py EVAL.csv ... [--tune-csv TUNE.csv ...]
"""
import argparse
import csv
import sys
from collections import defaultdict

import numpy as np

DATA_TERMS = ("rotation", "root_orientation", "position", "root_translation")


def load(paths):
    """{(dataset, content, clip, task, row, start): {method: row dict}}"""
    windows = defaultdict(dict)
    for path in paths:
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                key = (r["dataset"], r["content"] or r["rig"], r["clip"], r["task"], r["row"], r["start"])
                windows[key][r["method"]] = r
    return {k: v for k, v in windows.items() if {"interp", "nemf-detail"} <= set(v)}


def number(row, name):
    v = row.get(name, "") if row else ""
    return float(v) if v not in ("", None) else np.nan


def data_energy(row, stage):
    vals = [number(row, f"{stage}.{t}") for t in DATA_TERMS]
    vals = [v for v in vals if not np.isnan(v)]
    return sum(vals) if vals else np.nan


RULE_SIGNAL = "final data terms (nemf-detail)"
RULE_SIGNAL_PER_CM = "final data terms / key motion"
SIGNALS = {
    "final data terms (nemf-detail)": lambda w: data_energy(w["nemf-detail"], "final"),
    "initial data terms (detail start, encoded)": lambda w: data_energy(w["nemf-detail"], "initial"),
    "final / initial data terms": lambda w: data_energy(w["nemf-detail"], "final")
    / max(data_energy(w["nemf-detail"], "initial"), 1e-12),
    "final data terms / key motion": lambda w: data_energy(w["nemf-detail"], "final")
    / max(number(w["interp"], "key_motion_cm"), 1e-6),
    "final rotation term": lambda w: number(w["nemf-detail"], "final.rotation"),
    "final position term": lambda w: number(w["nemf-detail"], "final.position"),
    "final total energy": lambda w: sum(
        number(w["nemf-detail"], k) for k in w["nemf-detail"] if k.startswith("final.") and w["nemf-detail"][k] != ""
    ),
    "detail start to interp (L2P units)": lambda w: number(w.get("detail"), "l2p_to_interp"),
    "nemf-detail to interp (L2P units)": lambda w: number(w["nemf-detail"], "l2p_to_interp"),
    "detail to interp / key motion": lambda w: number(w.get("detail"), "l2p_to_interp")
    / max(number(w["interp"], "key_motion_cm"), 1e-6),
    "nemf-detail to interp / key motion": lambda w: number(w["nemf-detail"], "l2p_to_interp")
    / max(number(w["interp"], "key_motion_cm"), 1e-6),
    "- key motion (cm; small = still)": lambda w: -number(w["interp"], "key_motion_cm"),
}


def auc(score, label):
    """Mann-Whitney AUC of `score` for label 1 over label 0 (ties count half)."""
    ok = ~np.isnan(score)
    score, label = score[ok], label[ok]
    pos, neg = score[label], score[~label]
    if len(pos) == 0 or len(neg) == 0:
        return np.nan
    order = np.argsort(np.concatenate([pos, neg]), kind="mergesort")
    allv = np.concatenate([pos, neg])[order]
    ranks = np.empty(len(allv))
    i = 0
    while i < len(allv):  # average ranks of ties
        j = i
        while j + 1 < len(allv) and allv[j + 1] == allv[i]:
            j += 1
        ranks[i : j + 1] = (i + j) / 2.0 + 1
        i = j + 1
    r = np.empty(len(allv))
    r[order] = ranks
    return (r[: len(pos)].sum() - len(pos) * (len(pos) + 1) / 2.0) / (len(pos) * len(neg))


def hard_ratio(s, nemf, interp, t):
    chosen = np.where(s > t, interp, nemf)
    return chosen.mean() / interp.mean(), float((s > t).mean())


def soft_ratio(s, nemf, interp, t0, t1):
    w = np.clip((s - t0) / max(t1 - t0, 1e-12), 0.0, 1.0)
    return ((1 - w) * nemf + w * interp).mean() / interp.mean(), float(w.mean())


def tune(s, nemf, interp, groups):
    """Thresholds minimising the worst per-group ratio, then the mean ratio, over `groups`
    (lists of index arrays); candidates are the signal's quantiles."""
    qs = np.unique(np.nanquantile(s, np.linspace(0, 1, 41)))
    cands = list(qs) + [np.inf]

    def objective(ratio_of):
        ratios = [ratio_of(g) for g in groups]
        return (max(ratios), float(np.mean(ratios)))

    best_t = min(cands, key=lambda t: objective(lambda g: hard_ratio(s[g], nemf[g], interp[g], t)[0]))
    pairs = [(a, b) for i, a in enumerate(qs) for b in qs[i + 1 :]] + [(np.inf, np.inf + 1)]
    best_soft = min(pairs, key=lambda p: objective(lambda g: soft_ratio(s[g], nemf[g], interp[g], *p)[0]))
    return best_t, best_soft


def by_row(windows):
    rows = defaultdict(list)
    for key, w in windows.items():
        rows[(key[3], key[4])].append((key, w))
    return rows


def arrays(items):
    """Keys, interp's and nemf-detail's L2P, the label, the groups' indices and every signal."""
    keys = [k for k, _ in items]
    ws = [w for _, w in items]
    interp = np.array([number(w["interp"], "l2p") for w in ws])
    nemf = np.array([number(w["nemf-detail"], "l2p") for w in ws])
    groups = sorted({(k[0], k[1]) for k in keys})
    idx = {g: np.array([i for i, k in enumerate(keys) if (k[0], k[1]) == g]) for g in groups}
    signals = {name: np.array([f(w) for w in ws], dtype=float) for name, f in SIGNALS.items()}
    return interp, nemf, nemf > interp, idx, signals


def report_row(task, row, tune_items, eval_items, tune_label):
    t_interp, t_nemf, _, t_idx, t_signals = arrays(tune_items)
    interp, nemf, worse, idx, signals = arrays(eval_items)
    print(f"\n## {task} {row}: {len(eval_items)} windows evaluated, {len(tune_items)} to choose thresholds on\n")
    print("| group | windows | worse than interp | nemf-detail / interp | oracle |")
    print("|---|---:|---:|---:|---:|")
    for g, i in idx.items():
        oracle = np.minimum(nemf[i], interp[i]).mean() / interp[i].mean()
        print(f"| {g[0]} / {g[1]} | {len(i)} | {worse[i].mean():.2f} | {nemf[i].mean() / interp[i].mean():.3f} |"
              f" {oracle:.3f} |")
    print(f"\nThresholds chosen on: {tune_label}; per group: AUC, then fallback ratio (fraction falling back), "
          "soft-blend bound (mean weight).\n")
    print("| signal | AUC, all windows | " + " | ".join(f"{g[1]} ({g[0]})" for g in idx) + " | hard t | soft t0..t1 |")
    print("|---|---:|" + "---|" * len(idx) + "---|---|")
    for name, s in signals.items():
        if np.all(np.isnan(s)):
            continue
        ts = np.where(np.isnan(t_signals[name]), -np.inf, t_signals[name])  # no signal: no fallback
        t, (t0, t1) = tune(ts, t_nemf, t_interp, list(t_idx.values()))
        s_filled = np.where(np.isnan(s), -np.inf, s)
        cells = []
        for i in idx.values():
            h, hf = hard_ratio(s_filled[i], nemf[i], interp[i], t)
            b, bw = soft_ratio(s_filled[i], nemf[i], interp[i], t0, t1)
            cells.append(f"AUC {auc(s[i], worse[i]):.2f}; {h:.3f} ({hf:.2f}); {b:.3f} ({bw:.2f})")
        print(f"| {name} | {auc(s, worse):.2f} | " + " | ".join(cells) + f" | {t:.4g} | {t0:.4g}..{t1:.4g} |")


def quantile_table(eval_items):
    """10th, 50th and 90th percentile of every signal per group."""
    _, _, _, idx, signals = arrays(eval_items)
    print("\n| signal: 10th / 50th / 90th percentile | " + " | ".join(f"{g[1]} ({g[0]})" for g in idx) + " |")
    print("|---|" + "---|" * len(idx))
    for name, s in signals.items():
        if np.all(np.isnan(s)):
            continue
        cells = [" / ".join(f"{v:.4g}" for v in np.nanquantile(s[i], [0.1, 0.5, 0.9])) for i in idx.values()]
        print(f"| {name} | " + " | ".join(cells) + " |")


def fixed_rule(task, row, eval_items, t, t_per_cm):
    """The fallback "interpolation when the final data terms exceed t and, divided by the key
    motion, t_per_cm", per group."""
    interp, nemf, _, idx, signals = arrays(eval_items)
    data = np.nan_to_num(signals[RULE_SIGNAL], nan=-np.inf)
    per_cm = np.nan_to_num(signals[RULE_SIGNAL_PER_CM], nan=-np.inf)
    s = np.where((data > t) & (per_cm > t_per_cm), 1.0, 0.0)
    cells = []
    for g, i in idx.items():
        h, hf = hard_ratio(s[i], nemf[i], interp[i], 0.5)
        cells.append(f"{g[1]} ({g[0]}): {nemf[i].mean() / interp[i].mean():.3f} -> {h:.3f} ({hf:.2f} fall back)")
    print(f"\nFixed rule on {task} {row}, {RULE_SIGNAL} > {t:g} and per cm of key motion > {t_per_cm:g}: " + "; ".join(cells) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv", nargs="+", help="the windows to evaluate on")
    ap.add_argument("--tune-csv", nargs="+", default=None,
                    help="choose the thresholds on these windows instead (they are left out of the evaluation)")
    ap.add_argument("--fixed", type=float, default=None,
                    help="also report the fallback at this threshold of the final data terms")
    ap.add_argument("--fixed-per-cm", type=float, default=0.0,
                    help="with --fixed: fall back only when the final data terms per cm of key motion also exceed this")
    args = ap.parse_args()
    windows = load(args.csv)
    tune_windows = load(args.tune_csv) if args.tune_csv else windows
    if args.tune_csv:
        windows = {k: w for k, w in windows.items() if k not in tune_windows}
    if not windows or not tune_windows:
        sys.exit("no window with both interp and nemf-detail")
    tune_rows = by_row(tune_windows)
    label = ", ".join(args.tune_csv) if args.tune_csv else "the same windows (in-sample)"
    for (task, row), items in sorted(by_row(windows).items()):
        if (task, row) in tune_rows:
            report_row(task, row, tune_rows[(task, row)], items, label)
            quantile_table(items)
        if args.fixed is not None:
            fixed_rule(task, row, items, args.fixed, args.fixed_per_cm)


if __name__ == "__main__":
    main()
