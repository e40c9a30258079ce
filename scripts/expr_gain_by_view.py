#!/usr/bin/python3
"""Which test frames lose `expr_gain`: icef eval's per-frame scores by how large the frame's true
change is and how far its view lies from the training views.

`icef eval` writes, per test frame, `expr_gain` (the projection of the render's change on the true
change, over the true change's squared norm), `expr_corr` (their cosine), `expr_gain_coarse` (both
changes low-passed) and `expr_true_rms` (the true change's RMS over the region); docs/evaluation.md.
`expr_gain` = `expr_corr` x |m| / |t|, so `ratio` below (`expr_gain` / `expr_corr`) is how strong
the render's change is against the truth's, and `expr_corr` whether it lies where the truth's does.
This script reads EVAL_DIR/metrics.json and the dataset's transforms_train.json and
transforms_test.json and, tier by tier, averages those scores

- by change: the frames sorted by `expr_true_rms` and cut into --change-groups groups of equal size;
- within each run, the mean gain of the upper half of its frames minus that of the lower half, split
  at the run's median of: the angle between the test camera's direction from the aabb's centre and
  that of the nearest training camera; the true change's RMS; the test camera's elevation lying
  outside the range of the training cameras' (the y axis is up). Identities differ in both their
  views and their changes, so only differences within one run (one identity, one model) separate
  the two.

Several EVAL_DIR=DATASET pairs pool their frames (one trained model each). Usage:
  scripts/expr_gain_by_view.py EVAL_DIR=DATASET [EVAL_DIR=DATASET ...] [--tiers observed,near,moderate,far] [--json OUT]
"""
import argparse
import json
import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ beside the scripts
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from expr_gain_by_expression import load_json, mean  # noqa: E402


def camera_direction(frame, centre, where):
    m = frame.get("transform_matrix")
    if not (isinstance(m, list) and len(m) >= 3 and all(isinstance(r, list) and len(r) == 4 for r in m[:3])):
        raise SystemExit(f"{where}: transform_matrix: expected a 4x4 matrix")
    v = [m[a][3] - centre[a] for a in range(3)]
    n = math.sqrt(sum(x * x for x in v))
    if not n > 0:
        raise SystemExit(f"{where}: transform_matrix: the camera sits at the aabb's centre")
    return [x / n for x in v]


def elevation(d):
    return math.degrees(math.asin(max(-1.0, min(1.0, d[1]))))


def frame_rows(eval_dir, dataset, tiers):
    """[(angle to the nearest training view, elevation inside the training range, tier, gain, corr,
    coarse, true rms)] of the frames of `tiers` with a score."""
    metrics = load_json(os.path.join(eval_dir, "metrics.json"))
    train = load_json(os.path.join(dataset, "transforms_train.json"))
    test = load_json(os.path.join(dataset, "transforms_test.json"))
    aabb = test.get("aabb", train.get("aabb"))
    if not (isinstance(aabb, list) and len(aabb) == 2 and all(isinstance(c, list) and len(c) == 3 for c in aabb)):
        raise SystemExit(f"{dataset}/transforms_test.json: aabb: expected [[x, y, z], [x, y, z]]")
    centre = [(aabb[0][a] + aabb[1][a]) / 2 for a in range(3)]
    train_dirs = [camera_direction(f, centre, f"{dataset}/transforms_train.json: {f.get('file_path')}")
                  for f in train["frames"]]
    if not train_dirs:
        raise SystemExit(f"{dataset}/transforms_train.json: no frames")
    lo, hi = min(map(elevation, train_dirs)), max(map(elevation, train_dirs))
    by_path = {f["file_path"]: f for f in test["frames"]}
    rows = []
    for f in metrics["frames"]:
        if f.get("tier") not in tiers or f.get("expr_gain") is None:
            continue
        if f["file_path"] not in by_path:
            raise SystemExit(f"{dataset}/transforms_test.json: no frame {f['file_path']} (of {eval_dir}/metrics.json)")
        d = camera_direction(by_path[f["file_path"]], centre, f"{dataset}/transforms_test.json: {f['file_path']}")
        angle = min(math.degrees(math.acos(max(-1.0, min(1.0, sum(a * b for a, b in zip(d, t)))))) for t in train_dirs)
        rows.append((angle, lo <= elevation(d) <= hi, f["tier"], f["expr_gain"], f.get("expr_corr"),
                     f.get("expr_gain_coarse"), f.get("expr_true_rms")))
    return rows


def summary(rows):
    ratios = [r[3] / r[4] for r in rows if r[4]]
    return {"frames": len(rows), "expr_gain": mean([r[3] for r in rows]), "expr_corr": mean([r[4] for r in rows]),
            "ratio": mean(ratios), "expr_gain_coarse": mean([r[5] for r in rows]),
            "expr_true_rms": mean([r[6] for r in rows])}


def split_difference(rows, key):
    """Mean gain of the frames at or above the median of key minus that of the frames below it; for
    a yes/no key (True / False), of the frames with yes minus those with no. None when a side is empty."""
    values = sorted(key(r) for r in rows)
    cut = True if isinstance(values[0], bool) else values[len(values) // 2]
    upper = [r[3] for r in rows if key(r) >= cut]
    lower = [r[3] for r in rows if key(r) < cut]
    return mean(upper) - mean(lower) if upper and lower else None


def tables(runs, change_groups):
    """The tables of one tier (or one union of tiers): runs maps a pair to its rows."""
    rows = [r for g in runs.values() for r in g]
    by_change = {}
    ordered = sorted(rows, key=lambda r: r[6] if r[6] is not None else 0.0)
    n = len(ordered)
    for q in range(change_groups):
        g = ordered[q * n // change_groups:(q + 1) * n // change_groups]
        if g:
            by_change[f"true rms {g[0][6]:.4f}-{g[-1][6]:.4f}"] = summary(g)
    # Within each run (one model, one identity): identities differ in both their views and their
    # changes, so pooled groups would compare identities; the halves of one run's frames do not.
    within = {}
    for name, key in (("farther view", lambda r: r[0]), ("larger true change", lambda r: r[6] or 0.0),
                      ("elevation outside the training range", lambda r: not r[1])):
        d = [split_difference(g, key) for g in runs.values() if len(g) > 1]
        d = [x for x in d if x is not None]
        if d:
            within[name] = {"runs": len(d), "mean_gain_difference": mean(d), "runs_positive": sum(x > 0 for x in d)}
    return {"by_change": by_change, "all": summary(rows), "within_runs": within}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("pairs", nargs="+", help="EVAL_DIR=DATASET")
    ap.add_argument("--tiers", default="observed,near", help="comma-separated tiers, each reported on its own")
    ap.add_argument("--change-groups", type=int, default=4, help="groups of equal size by the true change's RMS")
    ap.add_argument("--json", help="also write the tables here")
    args = ap.parse_args()
    if args.change_groups < 1:
        raise SystemExit("--change-groups: expected at least 1")
    for pair in args.pairs:
        if "=" not in pair:
            raise SystemExit(f"expected EVAL_DIR=DATASET, got '{pair}'")
    report = {}
    for tier in args.tiers.split(","):
        runs = {pair: frame_rows(*pair.split("=", 1), {tier}) for pair in args.pairs}
        if not any(runs.values()):
            raise SystemExit(f"no scored frames in the tier '{tier}'")
        report[tier] = tables(runs, args.change_groups)

    fmt = lambda v: "     -" if v is None else f"{v:6.3f}"
    for tier, t in report.items():
        print(f"tier {tier}, by true change:")
        print(f"{'':>28} {'n':>4} {'gain':>6} {'corr':>6} {'ratio':>6} {'coarse':>6}")
        for label, g in list(t["by_change"].items()) + [("all", t["all"])]:
            print(f"{label:>28} {g['frames']:4d} {fmt(g['expr_gain'])} {fmt(g['expr_corr'])} {fmt(g['ratio'])} "
                  f"{fmt(g['expr_gain_coarse'])}")
        print("  within each run, gain of the upper half minus the lower half of its frames by:")
        for label, w in t["within_runs"].items():
            print(f"{label:>38}: {w['mean_gain_difference']:+.3f} (mean of {w['runs']} runs, {w['runs_positive']} positive)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"pairs": args.pairs, "tiers": report}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
