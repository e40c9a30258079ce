#!/usr/bin/python3
"""Which expressions lose `expr_gain`: icef eval's per-frame expression scores grouped by what the
frame's expression holds.

`icef eval` writes, per test frame, `expr_gain` (pixels) and `expr_gain_coarse` (both changes
low-passed: the expression at the scale of the features); docs/evaluation.md. This script reads
EVAL_DIR/metrics.json and the dataset's transforms_test.json and averages both over the frames of
each group:

- per expression: the frames in which that weight is at least --threshold (a frame with several
  such weights counts in each of their groups);
- `eye closure` / `no eye closure`: the frames with an eye_close_* weight of at least --threshold,
  and the rest (each frame in exactly one of the two);
- `all`: every frame with a score (frames whose true change is negligible have none).

Several EVAL_DIR=DATASET pairs pool their frames. Usage:
  scripts/expr_gain_by_expression.py EVAL_DIR=DATASET [EVAL_DIR=DATASET ...] [--threshold 0.25] [--json OUT]
"""
import argparse
import json
import os
import sys

EYES = ("eye_close_left", "eye_close_right")


def load_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        raise SystemExit(f"{path}: cannot read: {e}")


def frame_scores(eval_dir, dataset):
    """[(expression by name, tier, expr_gain, expr_gain_coarse)] of the frames with a score."""
    metrics = load_json(os.path.join(eval_dir, "metrics.json"))
    test = load_json(os.path.join(dataset, "transforms_test.json"))
    names = test["expression_names"]
    by_path = {f["file_path"]: f for f in test["frames"]}
    rows = []
    for f in metrics["frames"]:
        if f["file_path"] not in by_path:
            raise SystemExit(f"{dataset}/transforms_test.json: no frame {f['file_path']} (of {eval_dir}/metrics.json)")
        if f.get("expr_gain") is None:
            continue
        weights = dict(zip(names, by_path[f["file_path"]]["expression"]))
        rows.append((weights, f.get("tier"), f["expr_gain"], f.get("expr_gain_coarse")))
    return rows


def mean(values):
    values = [v for v in values if v is not None]
    return sum(values) / len(values) if values else None


def group(rows, threshold):
    groups = {}

    def add(name, row):
        groups.setdefault(name, []).append(row)

    for row in rows:
        weights = row[0]
        add("all", row)
        add("eye closure" if any(weights.get(e, 0) >= threshold for e in EYES) else "no eye closure", row)
        for name, w in weights.items():
            if w >= threshold:
                add(name, row)
    return {name: {"frames": len(g), "expr_gain": mean([r[2] for r in g]), "expr_gain_coarse": mean([r[3] for r in g])}
            for name, g in groups.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("pairs", nargs="+", help="EVAL_DIR=DATASET")
    ap.add_argument("--threshold", type=float, default=0.25, help="a weight at least this puts a frame in its group")
    ap.add_argument("--json", help="also write the table here")
    args = ap.parse_args()
    rows = []
    for pair in args.pairs:
        if "=" not in pair:
            raise SystemExit(f"expected EVAL_DIR=DATASET, got '{pair}'")
        eval_dir, dataset = pair.split("=", 1)
        rows += frame_scores(eval_dir, dataset)
    table = group(rows, args.threshold)
    fmt = lambda v: "   -" if v is None else f"{v:6.3f}"
    order = ["all", "eye closure", "no eye closure"] + sorted(k for k in table if k not in ("all", "eye closure", "no eye closure"))
    print(f"{'frames with':>18} {'n':>4} {'gain':>6} {'coarse':>6}")
    for name in order:
        if name in table:
            t = table[name]
            print(f"{name:>18} {t['frames']:4d} {fmt(t['expr_gain'])} {fmt(t['expr_gain_coarse'])}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"pairs": args.pairs, "threshold": args.threshold, "groups": table}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
