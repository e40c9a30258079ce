#!/usr/bin/python3
"""Where a tier's expression is lost: `expr_gain` pooled over the test frames, feature by feature.

`expr_gain` (docs/evaluation.md) projects the model's change m (render - the model's neutral render,
same view) on the true change t (ground truth - its neutral) over the brow/eye/mouth region, frame by
frame, and the tier's figure is the mean over its frames. This script splits the same region into
features and pools over the frames of a tier:

- features: the brows (iBUG 17-26), the right eye (36-41), the left eye (42-47) and the mouth
  (48-67), each the convex hull of the frame's and its neutral's landmarks of that feature, dilated
  by 3 px at 128 px (scaled with the width, as eval's region); a pixel goes to the first feature
  in that order whose area holds it;
- per feature: `share`, its part of sum <t, t> over the tier's frames, and `gain`, the pooled
  sum <m, t> / sum <t, t>: how much of the expression that feature reproduces, weighted by how
  much expression it carries;
- `all`: the same pooled over the four features together.

A pooled gain weights frames by their true change, so it is not the tier's `expr_gain` (a plain
mean over frames, where a frame with a small change counts as much as one with a large change).
Computed from the 8-bit PNGs that `icef eval` writes, composited over white.

Usage:
  scripts/expr_gain_regions.py EVAL_DIR=DATASET [EVAL_DIR=DATASET ...] [--tiers near,observed] [--json OUT]

EVAL_DIR holds `icef eval`'s metrics.json and renders/ (test_NNN.png, neutral_NNN.png); DATASET is
the dataset it was evaluated on (transforms_test.json with each frame's neutral_file_path).
"""
import argparse
import json
import os
import sys

import numpy as np
from PIL import Image, ImageDraw
from scipy import ndimage
from scipy.spatial import ConvexHull

FEATURES = (("brows", range(17, 27)), ("right_eye", range(36, 42)), ("left_eye", range(42, 48)),
            ("mouth", range(48, 68)))


def fail(message):
    print("expr_gain_regions: " + message, file=sys.stderr)
    sys.exit(1)


def load_rgb(path):
    try:
        a = np.asarray(Image.open(path).convert("RGBA"), dtype=np.float64) / 255.0
    except (OSError, ValueError) as e:
        fail(f"{path}: cannot read the image ({e})")
    return a[..., :3] * a[..., 3:] + (1.0 - a[..., 3:])


def feature_mask(points, height, width, dilation):
    points = np.asarray([p for p in points if np.all(np.isfinite(p))], dtype=np.float64)
    mask = np.zeros((height, width), bool)
    if len(points) < 3:
        return mask
    hull = ConvexHull(points)
    image = Image.new("L", (width, height), 0)
    # Landmarks have pixel centres at +0.5; PIL's polygon fill takes centres at integers.
    ImageDraw.Draw(image).polygon([tuple(p - 0.5) for p in points[hull.vertices]], fill=1)
    inside = np.asarray(image) > 0
    return ndimage.distance_transform_edt(~inside) <= dilation


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pairs", nargs="+", help="EVAL_DIR=DATASET")
    parser.add_argument("--tiers", default="observed,near,moderate,far")
    parser.add_argument("--json", help="write the table here as JSON")
    args = parser.parse_args()
    tiers = args.tiers.split(",")
    sums = {t: {name: [0.0, 0.0] for name, _ in FEATURES} for t in tiers}
    frames = {t: 0 for t in tiers}
    for pair in args.pairs:
        if "=" not in pair:
            fail(f"{pair}: expected EVAL_DIR=DATASET")
        eval_dir, dataset = pair.split("=", 1)
        path = os.path.join(dataset, "transforms_test.json")
        try:
            test = json.load(open(path))["frames"]
        except (OSError, ValueError, KeyError) as e:
            fail(f"{path}: cannot read the test frames ({e})")
        for i, f in enumerate(test):
            tier = f.get("tier")
            if tier not in sums:
                continue
            if "neutral_file_path" not in f or "landmarks_2d" not in f:
                fail(f"{path}: frame {i} has no neutral_file_path or landmarks_2d")
            truth = load_rgb(os.path.join(dataset, f["file_path"]))
            truth_neutral = load_rgb(os.path.join(dataset, f["neutral_file_path"]))
            neutral_index = os.path.splitext(f["neutral_file_path"])[0].rsplit("_", 1)[-1]
            render = load_rgb(os.path.join(eval_dir, "renders", f"test_{i:03d}.png"))
            render_neutral = load_rgb(os.path.join(eval_dir, "renders", f"neutral_{neutral_index}.png"))
            t = truth - truth_neutral
            m = render - render_neutral
            h, w = t.shape[:2]
            dilation = max(1, round(3 * w / 128))
            own = np.asarray(f["landmarks_2d"], dtype=np.float64)
            neutral = np.asarray(f.get("neutral_landmarks_2d", f["landmarks_2d"]), dtype=np.float64)
            claimed = np.zeros((h, w), bool)
            for name, idx in FEATURES:
                idx = list(idx)
                mask = feature_mask(np.concatenate([own[idx], neutral[idx]]), h, w, dilation) & ~claimed
                claimed |= mask
                sums[tier][name][0] += float((m * t)[mask].sum())
                sums[tier][name][1] += float((t * t)[mask].sum())
            frames[tier] += 1
    table = {}
    for tier in tiers:
        total_mt = sum(v[0] for v in sums[tier].values())
        total_tt = sum(v[1] for v in sums[tier].values())
        if total_tt <= 0:
            continue
        row = {name: {"share": tt / total_tt, "gain": mt / tt if tt > 0 else None}
               for name, (mt, tt) in sums[tier].items()}
        row["all"] = {"share": 1.0, "gain": total_mt / total_tt}
        row["frames"] = frames[tier]
        table[tier] = row
        cells = "  ".join(f"{name} {row[name]['gain']:.3f} ({row[name]['share']:.2f})" for name, _ in FEATURES)
        print(f"{tier:9s} frames {frames[tier]:3d}  {cells}  all {row['all']['gain']:.3f}")
    if args.json:
        with open(args.json + ".tmp", "w") as out:
            json.dump(table, out, indent=1)
        os.replace(args.json + ".tmp", args.json)


if __name__ == "__main__":
    main()
