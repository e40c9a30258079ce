#!/usr/bin/python3
"""Where `expr_gain` is lost: the measure at several spatial scales, for renders and for references.

`icef eval` measures expr_gain = <m, t> / <t, t> on pixels (docs/evaluation.md), with m = render -
the model's neutral render and t = ground truth - its neutral, inside the expression region. This
script recomputes it from an eval directory and its dataset, after low-passing m and t with the same
Gaussian (sigma in pixels; 0 = the pixel measure icef eval reports), per tier:

- `render`: the eval directory's renders (as icef eval measures them);
- `blurred truth S`: the ground truth and its neutral blurred by a Gaussian of S pixels, as a
  render that has every bit of the expression but is that soft would score;
- `--reference DIR`: the test images of another dataset of the same views and expressions (e.g.
  `icef synth --generic-style`: the face model's generic expressions, which is what the prior knows;
  `icef synth --canonical-shading`: the same expressions with the shading moving with the skin, what
  a warp of a static field can reproduce at best), with `--reference-blur S,...` also blurred.

A render whose score rises to near 1 when measured at a coarser scale has the expression but lacks
its pixel-scale sharpness; one that stays low does not move the face as the truth does.

Usage: scripts/expr_gain_probe.py DATASET EVAL_DIR [--reference DATASET2 [--reference-blur S,...]] [--json OUT]
"""
import argparse
import json
import os
import sys

import numpy as np
from PIL import Image, ImageDraw

SCALES = [0, 1, 2, 3]
TIERS = ["observed", "near", "moderate", "far"]
REGION = list(range(17, 27)) + list(range(36, 68))  # brows, eyes, mouth (iBUG)


def load(path, background):
    a = np.asarray(Image.open(path).convert("RGBA"), dtype=np.float64) / 255.0
    return a[..., :3] * a[..., 3:] + (1.0 - a[..., 3:]) * background


def blur(image, sigma):
    if sigma <= 0:
        return image
    r = int(np.ceil(3 * sigma))
    k = np.exp(-np.arange(-r, r + 1) ** 2 / (2 * sigma * sigma))
    k /= k.sum()
    out = image
    for axis in (0, 1):
        pad = [(0, 0)] * out.ndim
        pad[axis] = (r, r)
        p = np.pad(out, pad, mode="edge")
        out = sum(k[i] * np.take(p, range(i, i + out.shape[axis]), axis=axis) for i in range(2 * r + 1))
    return out


def hull_mask(landmarks, width, height, dilation):
    pts = sorted({(float(x), float(y)) for x, y in (landmarks[i] for i in REGION)})

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
    mask = Image.new("L", (width, height), 0)
    ImageDraw.Draw(mask).polygon([(x - 0.5, y - 0.5) for x, y in lower[:-1] + upper[:-1]], fill=1)
    m = np.asarray(mask).astype(bool)
    for _ in range(dilation):  # approximately icef eval's distance dilation
        g = m.copy()
        g[1:] |= m[:-1]
        g[:-1] |= m[1:]
        g[:, 1:] |= m[:, :-1]
        g[:, :-1] |= m[:, 1:]
        m = g
    return m


def gain(m, t, region, sigma):
    mb, tb = blur(m, sigma)[region], blur(t, sigma)[region]
    return float((mb * tb).sum() / (tb * tb).sum())


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset")
    ap.add_argument("eval_dir")
    ap.add_argument("--reference", help="dataset with the same test views and expressions (e.g. --generic-style)")
    ap.add_argument("--reference-blur", default="", help="also the reference blurred by these Gaussian sigmas (pixels)")
    ap.add_argument("--truth-blur", default="0.5,0.7,1.0", help="Gaussian sigmas (pixels) of the blurred-truth rows")
    ap.add_argument("--json", help="also write the table here")
    args = ap.parse_args()
    meta = json.load(open(os.path.join(args.dataset, "transforms_test.json")))
    bg = np.array(meta.get("background", [1, 1, 1])[:3], dtype=np.float64)
    rows = {"render": {}}
    blurs = [float(s) for s in args.truth_blur.split(",") if s]
    reference_blurs = [float(s) for s in args.reference_blur.split(",") if s]
    for f in meta["frames"]:
        tier = f.get("tier", "observed")
        if "neutral_file_path" not in f or "landmarks_2d" not in f:
            continue
        truth = load(os.path.join(args.dataset, f["file_path"]), bg)
        neutral = load(os.path.join(args.dataset, f["neutral_file_path"]), bg)
        h, w, _ = truth.shape
        region = hull_mask(f["landmarks_2d"], w, h, max(1, round(3 * w / 128)))
        region |= hull_mask(f["neutral_landmarks_2d"], w, h, max(1, round(3 * w / 128)))
        t = truth - neutral
        if np.sqrt((t[region] ** 2).mean()) < 0.004:  # negligible true change: no gain (as icef eval)
            continue
        stem = os.path.basename(f["file_path"])
        nstem = os.path.basename(f["neutral_file_path"]).replace("test_neutral", "neutral")
        candidates = {"render": (os.path.join(args.eval_dir, "renders", stem),
                                 os.path.join(args.eval_dir, "renders", nstem))}
        if args.reference:
            candidates["reference"] = (os.path.join(args.reference, f["file_path"]),
                                       os.path.join(args.reference, f["neutral_file_path"]))
        for name, (a, b) in candidates.items():
            changed, still = load(a, bg), load(b, bg)
            for s in [0.0] + (reference_blurs if name == "reference" else []):
                m = blur(changed, s) - blur(still, s)
                row = name if s == 0 else f"{name} blurred {s:g}"
                rows.setdefault(row, {}).setdefault(tier, []).append([gain(m, t, region, sc) for sc in SCALES])
        for s in blurs:
            m = blur(truth, s) - blur(neutral, s)
            rows.setdefault(f"blurred truth {s:g}", {}).setdefault(tier, []).append(
                [gain(m, t, region, sc) for sc in SCALES])
    table = {name: {tier: np.mean(v, axis=0).round(3).tolist() for tier, v in tiers.items()}
             for name, tiers in rows.items()}
    print(f"expr_gain per tier, measured after a Gaussian low-pass of sigma = {SCALES} px (0 = icef eval's)")
    for name, tiers in table.items():
        for tier in TIERS:
            if tier in tiers:
                print(f"  {name:20s} {tier:9s} " + "  ".join(f"{v:5.2f}" for v in tiers[tier]))
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"scales_px": SCALES, "dataset": args.dataset, "eval": args.eval_dir,
                       "reference": args.reference, "expr_gain": table}, out, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
