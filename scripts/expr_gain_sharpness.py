#!/usr/bin/python3
"""How much `expr_gain` a render's softness costs: the truth's own score when blurred, and how soft
the renders are.

`expr_gain` (docs/evaluation.md) projects the render's change (render - the model's neutral render)
on the true change (truth - its neutral) in the brow/eye/mouth region. Most true changes near the
observed expressions are edges that move by a pixel or two (a lid, a lip line, a brow), so a
render that has every edge in the right place but a little soft scores well below 1. This script
measures both sides of that, per tier, over the test frames of one or more EVAL_DIR=DATASET pairs:

- `truth_blurred`: the `expr_gain` of the ground truth itself, both the frame and its neutral
  blurred by a Gaussian of sigma px (the same region and formula as icef eval), for each --sigmas;
- `render_sigma`: the sigma whose blurred truth the render matches best (least squared error in
  the region), averaged over the frames: the render's softness in pixels;
- `train_sigma`: the same for the training-view fit renders (EVAL_DIR/renders/fit_*.png) against
  the training images, inside the hull of all their landmarks;
- `expr_gain`: icef eval's own per-tier mean over the same frames, and `mean_gain_mismatch`, the
  mean difference between it and this script's recomputation of each frame's score from the
  8-bit PNG renders (a check that the region and formula here are eval's; eval scores the
  renders before they are rounded to 8 bits, which moves a frame with a tiny true change most).

Usage:
  scripts/expr_gain_sharpness.py EVAL_DIR=DATASET [EVAL_DIR=DATASET ...] [--sigmas 0.25,0.5,...] [--json OUT]
"""
import argparse
import json
import math
import os
import sys

import numpy as np
from PIL import Image

TIERS = ("observed", "near", "moderate", "far")
# eval/expression_fidelity.cc, ExpressionLandmarkIndices: brows, eyes, mouth.
REGION_LANDMARKS = list(range(17, 27)) + list(range(36, 68))
FIT_SIGMAS = [0.05 * i for i in range(0, 31)]  # 0 .. 1.5 px, for render_sigma / train_sigma


def fail(message):
    print(f"expr_gain_sharpness: {message}", file=sys.stderr)
    sys.exit(1)


def load_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{path}: {e}")


def load_image(path):
    try:
        return np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255.0
    except OSError as e:
        fail(f"{path}: {e}")


def gaussian_blur(image, sigma):
    """A Gaussian of sigma px integrated over each pixel (well defined below a pixel too)."""
    if sigma <= 0:
        return image
    r = max(1, int(np.ceil(3 * sigma + 0.5)))
    edges = [0.5 * (1 + math.erf((i + 0.5) / (sigma * math.sqrt(2)))) for i in range(-r - 1, r + 1)]
    k = np.diff(edges)
    k /= k.sum()
    padded = np.pad(image, ((r, r), (r, r), (0, 0)), mode="edge")
    rows = sum(k[i] * padded[:, i:i + image.shape[1]] for i in range(2 * r + 1))
    return sum(k[i] * rows[i:i + image.shape[0]] for i in range(2 * r + 1))


def convex_hull(points):
    pts = sorted(set(points))
    if len(pts) < 3:
        return pts

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def in_dilated_hull(hull, px, py, dilation):
    """Pixel centres (px, py) inside the counter-clockwise hull or within `dilation` of it."""
    inside = np.ones(px.shape, bool)
    dist = np.full(px.shape, np.inf)
    n = len(hull)
    for i in range(n):
        ax, ay = hull[i]
        bx, by = hull[(i + 1) % n]
        inside &= (bx - ax) * (py - ay) - (by - ay) * (px - ax) >= 0
        ex, ey = bx - ax, by - ay
        len2 = ex * ex + ey * ey
        s = np.clip(((px - ax) * ex + (py - ay) * ey) / len2, 0, 1) if len2 > 0 else 0
        dist = np.minimum(dist, np.hypot(px - (ax + s * ex), py - (ay + s * ey)))
    if n < 3:
        inside[:] = False
    return inside | (dist <= dilation)


def region_mask(width, height, landmark_sets, indices, dilation):
    py, px = np.mgrid[0:height, 0:width] + 0.5
    mask = np.zeros((height, width), bool)
    for landmarks in landmark_sets:
        points = [tuple(landmarks[i]) for i in indices if i < len(landmarks) and np.all(np.isfinite(landmarks[i]))]
        hull = convex_hull(points)
        if hull:
            mask |= in_dilated_hull(hull, px, py, dilation)
    return mask[..., None]


def best_sigma(render, truth, mask):
    errors = [(((render - gaussian_blur(truth, s)) * mask) ** 2).sum() for s in FIT_SIGMAS]
    return FIT_SIGMAS[int(np.argmin(errors))]


def gain(change, true_change):
    return float((change * true_change).sum() / (true_change * true_change).sum())


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pairs", nargs="+", help="EVAL_DIR=DATASET")
    parser.add_argument("--sigmas", default="0.25,0.5,0.75,1.0", help="blur sigmas (px) for truth_blurred")
    parser.add_argument("--json", help="write the result here too")
    args = parser.parse_args()
    sigmas = [float(s) for s in args.sigmas.split(",")]
    per_tier = {t: {"frames": 0, "expr_gain": [], "truth_blurred": {s: [] for s in sigmas}, "render_sigma": []}
                for t in TIERS}
    train_sigma, mismatch = [], []
    for pair in args.pairs:
        if "=" not in pair:
            fail(f"{pair}: expected EVAL_DIR=DATASET")
        eval_dir, dataset = pair.split("=", 1)
        metrics = load_json(os.path.join(eval_dir, "metrics.json"))
        test = load_json(os.path.join(dataset, "transforms_test.json"))
        by_path = {f["file_path"]: f for f in metrics.get("frames", [])}
        for frame in test["frames"]:
            scored = by_path.get(frame["file_path"])
            if scored is None or scored.get("expr_gain") is None or frame.get("tier") not in per_tier:
                continue
            truth = load_image(os.path.join(dataset, frame["file_path"]))
            truth_neutral = load_image(os.path.join(dataset, frame["neutral_file_path"]))
            render = load_image(os.path.join(eval_dir, scored["render"]))
            stem = os.path.splitext(os.path.basename(frame["neutral_file_path"]))[0].replace("test_neutral_", "")
            render_neutral = load_image(os.path.join(eval_dir, "renders", f"neutral_{stem}.png"))
            h, w = truth.shape[:2]
            mask = region_mask(w, h, [frame["landmarks_2d"], frame["neutral_landmarks_2d"]], REGION_LANDMARKS,
                               max(1, round(3.0 * w / 128.0)))
            true_change = (truth - truth_neutral) * mask
            mismatch.append(abs(gain((render - render_neutral) * mask, true_change) - scored["expr_gain"]))
            t = per_tier[frame["tier"]]
            t["frames"] += 1
            t["expr_gain"].append(scored["expr_gain"])
            for s in sigmas:
                t["truth_blurred"][s].append(gain((gaussian_blur(truth, s) - gaussian_blur(truth_neutral, s)) * mask,
                                                  true_change))
            t["render_sigma"].append(best_sigma(render, truth, mask))
        train = load_json(os.path.join(dataset, "transforms_train.json"))
        for frame in train["frames"]:
            fit = os.path.join(eval_dir, "renders", "fit_" + os.path.basename(frame["file_path"]))
            if not os.path.exists(fit) or "landmarks_2d" not in frame:
                continue
            truth = load_image(os.path.join(dataset, frame["file_path"]))
            mask = region_mask(truth.shape[1], truth.shape[0], [frame["landmarks_2d"]],
                               range(len(frame["landmarks_2d"])), 0)
            train_sigma.append(best_sigma(load_image(fit), truth, mask))
    out = {"pairs": args.pairs, "sigmas": sigmas, "mean_gain_mismatch": float(np.mean(mismatch)) if mismatch else None,
           "train_sigma": float(np.mean(train_sigma)) if train_sigma else None, "tiers": {}}
    for name, t in per_tier.items():
        if not t["frames"]:
            continue
        out["tiers"][name] = {
            "frames": t["frames"],
            "expr_gain": float(np.mean(t["expr_gain"])),
            "render_sigma": float(np.mean(t["render_sigma"])),
            "truth_blurred": {f"{s:g}": float(np.mean(v)) for s, v in t["truth_blurred"].items()},
        }
    print(f"{'tier':9} {'frames':>6} {'expr_gain':>9} {'render_sigma':>12}  truth blurred by sigma px: "
          + "  ".join(f"{s:g}" for s in sigmas))
    for name, t in out["tiers"].items():
        print(f"{name:9} {t['frames']:6d} {t['expr_gain']:9.3f} {t['render_sigma']:12.2f}  "
              + "  ".join(f"{v:.3f}" for v in t["truth_blurred"].values()))
    if out["train_sigma"] is not None:
        print(f"training-view fit renders: sigma {out['train_sigma']:.2f} px")
    if mismatch:
        print(f"mean difference from icef eval's own expr_gain (renders read back from 8-bit PNGs): "
              f"{np.mean(mismatch):.1e}")
    if args.json:
        tmp = args.json + ".tmp"
        with open(tmp, "w") as f:
            json.dump(out, f, indent=1)
        os.replace(tmp, args.json)


if __name__ == "__main__":
    main()
