#!/usr/bin/python3
"""How well `icef track` recovers what it should, on synthetic photos with known truth.

For each identity seed: `icef synth --photos N` renders the procedural head (in the identity's own
expression style) at random head poses, sizes and offsets over a textured background, alpha
withheld; `icef track` turns the photos into a dataset; this script compares the tracked result
with truth/truth.json:

- rotation error: angle between the tracked and the true camera-to-head rotations (degrees);
- translation error: distance between the tracked and the true position of the head (the head
  frame's origin) in the camera frame, over the head's crown-to-chin height; split into its part
  along the line of sight (depth: with a known focal length, a head fitted x % too large is fitted
  x % too far, so this part carries the size error the shape prior leaves) and its part across it
  (lateral: where the head is in the image); `distance_ratio` is the tracked over the true
  camera-to-head distance; `translation_frac_scale_aligned` is the translation error after one
  factor per identity (`identity_scale`, least squares over its photos) takes out the head size a
  monocular tracker cannot tell from its distance;
- expression error: RMS over the 11 weights, and over the 10 the 68 landmarks can see (cheek_puff
  moves none of them), beside what predicting neutral would score; and the correlation of the
  tracked with the true weights over all photos;
- mask IoU: the dataset image's alpha against the true coverage cropped the same way.

Usage: scripts/track_eval.py --icef build/icef --out DIR [--seeds 1,2,3] [--photos 5] [--res 256] [--reuse]
(--reuse: evaluate DIR's photos and datasets as they are, without running icef again)
Writes DIR/track_eval.json and prints a table; exit 1 when --check bounds are exceeded.
"""
import argparse
import json
import math
import os
import subprocess
import sys

import numpy as np
from PIL import Image

HEAD_HEIGHT = 0.727  # crown (0.388) to chin (-0.339) of the average head, head units


def rotation_angle_deg(a, b):
    r = np.asarray(a)[:3, :3].T @ np.asarray(b)[:3, :3]
    c = (np.trace(r) - 1) / 2
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def align_scale(true_positions, tracked_positions):
    """The scale a monocular tracker cannot see: one factor for an identity's photos (they share the
    head), the least-squares s in true ~ s * tracked, as a scale-aligned trajectory error aligns a
    monocular camera's. Returns s and each photo's |true - s * tracked| (what the photos decide)."""
    tt, pt = np.asarray(true_positions, float), np.asarray(tracked_positions, float)
    s = float((tt * pt).sum() / (pt * pt).sum())
    return s, [float(e) for e in np.linalg.norm(tt - s * pt, axis=1)]


def median(values):
    return float(np.median(np.asarray(values))) if values else float("nan")


def evaluate_seed(icef, out, seed, photos, res, extra, synth_extra, reuse=False):
    photo_dir = os.path.join(out, f"photos_{seed}")
    data_dir = os.path.join(out, f"track_{seed}")
    if not reuse:
        for d in (photo_dir, data_dir):
            subprocess.run(["rm", "-rf", d], check=True)
        subprocess.run([icef, "synth", "--photos", str(photos), "--identity-seed", str(seed), "--out", photo_dir] + synth_extra,
                       check=True, stdout=subprocess.DEVNULL)
    truth = json.load(open(os.path.join(photo_dir, "truth", "truth.json")))
    # The true focal length (all photos of a set share it), unless the caller passes its own.
    focal = [] if "--focal" in extra else ["--focal", str(truth["photos"][0]["fl_x"])]
    if not reuse:
        subprocess.run([icef, "track", os.path.join(photo_dir, "photos"), "--out", data_dir, "--res", str(res), "--skip-bad"] + focal + extra,
                       check=True, stdout=subprocess.DEVNULL)
    report = json.load(open(os.path.join(data_dir, "track", "report.json")))
    names = truth["expression_names"]
    frames = {}
    for split in ("train", "test"):
        path = os.path.join(data_dir, f"transforms_{split}.json")
        if os.path.exists(path):
            for f in json.load(open(path))["frames"]:
                frames[f["file_path"]] = f
    rows = []
    for p in report["photos"]:
        t = next(x for x in truth["photos"] if os.path.basename(x["file"]) == os.path.basename(p["photo"]))
        f = frames[p["file_path"]]
        true_c2h = np.asarray(t["camera_to_head"])
        track_c2h = np.asarray(f["transform_matrix"])
        rot = rotation_angle_deg(true_c2h, track_c2h)
        # The head's position in the camera frame (head_in_camera = -R^T c).
        true_t = -true_c2h[:3, :3].T @ true_c2h[:3, 3]
        track_t = -track_c2h[:3, :3].T @ track_c2h[:3, 3]
        trans = float(np.linalg.norm(true_t - track_t)) / HEAD_HEIGHT
        sight = true_t / np.linalg.norm(true_t)
        depth = float(abs((track_t - true_t) @ sight)) / HEAD_HEIGHT
        lateral = float(np.linalg.norm((track_t - true_t) - ((track_t - true_t) @ sight) * sight)) / HEAD_HEIGHT
        distance_ratio = float(np.linalg.norm(track_t) / np.linalg.norm(true_t))
        te = np.array([t["expression"][n] for n in names])
        pe = np.array([p["expression"][n] for n in names])
        seen = [i for i, n in enumerate(names) if n != "cheek_puff"]
        expr_all = float(np.sqrt(np.mean((te - pe) ** 2)))
        expr_seen = float(np.sqrt(np.mean((te[seen] - pe[seen]) ** 2)))
        expr_zero = float(np.sqrt(np.mean(te ** 2)))  # what predicting neutral scores
        # The true coverage cropped like the dataset image.
        x0, y0, size = p["crop"]
        alpha = Image.open(os.path.join(photo_dir, t["alpha_file"])).convert("F")
        true_crop = np.asarray(alpha.transform((res, res), Image.EXTENT, (x0, y0, x0 + size, y0 + size),
                                               Image.BILINEAR)) / 255.0
        mask = np.asarray(Image.open(os.path.join(data_dir, f["file_path"])).convert("RGBA"))[..., 3] / 255.0
        a, b = true_crop > 0.5, mask > 0.5
        iou = float((a & b).sum() / max(1, (a | b).sum()))
        rows.append({"seed": seed, "photo": os.path.basename(p["photo"]), "rotation_deg": rot,
                     "translation_frac": trans, "depth_frac": depth, "lateral_frac": lateral,
                     "distance_ratio": distance_ratio, "true_head_in_camera": true_t.tolist(),
                     "tracked_head_in_camera": track_t.tolist(), "expression_rms": expr_all, "expression_rms_seen": expr_seen, "expression_rms_neutral": expr_zero,
                     "true_expression": te.tolist(), "tracked_expression": pe.tolist(),
                     "mask_iou": iou, "landmark_rms_iod": p["landmark_rms_iod"],
                     "true_pose_deg": t.get("head_pose_deg")})
    # The shape scales against the identity's true ones (truth.json "shape"), RMS over the 13.
    if "shape" in truth:
        err = [report["shape"][k] - v for k, v in truth["shape"].items()]
        for r in rows:
            r["shape_rms"] = float(np.sqrt(np.mean(np.square(err))))
    if rows:
        s, errors = align_scale([r["true_head_in_camera"] for r in rows], [r["tracked_head_in_camera"] for r in rows])
        for r, e in zip(rows, errors):
            r["identity_scale"] = s
            r["translation_frac_scale_aligned"] = e / HEAD_HEIGHT
    skipped = [{"seed": seed, "skipped": s} for s in report["skipped"]]
    return rows, skipped


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--icef", default="build/icef")
    ap.add_argument("--out", required=True)
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--photos", type=int, default=5)
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--check", default="", help="bounds 'rot,trans,expr,iou' on the medians (expr: the seen weights)")
    ap.add_argument("--track-args", default="", help="extra arguments for icef track")
    ap.add_argument("--synth-args", default="", help="extra arguments for icef synth --photos (e.g. --generic-style)")
    ap.add_argument("--reuse", action="store_true", help="evaluate OUT's photos and datasets as they are (no icef runs)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rows, skipped = [], []
    for seed in [int(s) for s in args.seeds.split(",")]:
        r, s = evaluate_seed(args.icef, args.out, seed, args.photos, args.res, args.track_args.split(),
                             args.synth_args.split(), args.reuse)
        rows += r
        skipped += s
    keys = ["rotation_deg", "translation_frac", "translation_frac_scale_aligned", "depth_frac", "lateral_frac", "expression_rms", "expression_rms_seen", "expression_rms_neutral",
            "mask_iou", "landmark_rms_iod"] + (["shape_rms"] if rows and "shape_rms" in rows[0] else [])
    summary = {k: {"median": median([r[k] for r in rows]), "max": max(r[k] for r in rows),
                   "min": min(r[k] for r in rows)} for k in keys}
    # How much of the expressions the tracker finds: correlation of the tracked with the true weights
    # (all photos, the 10 weights landmarks can see).
    names_seen = [i for i in range(11) if i != 10]
    t = np.array([r["true_expression"] for r in rows])[:, names_seen].ravel()
    p = np.array([r["tracked_expression"] for r in rows])[:, names_seen].ravel()
    summary["expression_correlation"] = float(np.corrcoef(t, p)[0, 1]) if t.std() > 0 and p.std() > 0 else 0.0
    summary["distance_ratio_error"] = {"median": median([abs(r["distance_ratio"] - 1) for r in rows])}
    summary["identity_scale"] = {str(r["seed"]): r["identity_scale"] for r in rows}
    print(f"{'seed':>4} {'photo':>14} {'rot deg':>8} {'trans':>7} {'aligned':>7} {'depth':>7} {'lateral':>7} {'expr':>6} {'expr10':>6} {'IoU':>6} {'lm IOD':>7}")
    for r in rows:
        print(f"{r['seed']:>4} {r['photo']:>14} {r['rotation_deg']:8.2f} {r['translation_frac']:7.3f} {r['translation_frac_scale_aligned']:7.3f} "
              f"{r['depth_frac']:7.3f} {r['lateral_frac']:7.3f} "
              f"{r['expression_rms']:6.3f} {r['expression_rms_seen']:6.3f} {r['mask_iou']:6.3f} {r['landmark_rms_iod']:7.3f}")
    for s in skipped:
        print(f"seed {s['seed']}: skipped {s['skipped']}")
    print("median " + "  ".join(f"{k} {summary[k]['median']:.3f}" for k in keys) +
          f"  expression_correlation {summary['expression_correlation']:.3f}")
    with open(os.path.join(args.out, "track_eval.json"), "w") as f:
        json.dump({"seeds": args.seeds, "photos": args.photos, "res": args.res, "summary": summary, "rows": rows,
                   "skipped": skipped}, f,
                  indent=1)
    if args.check:
        rot, trans, expr, iou = (float(x) for x in args.check.split(","))
        s = summary
        bad = []
        if s["rotation_deg"]["median"] > rot: bad.append(f"median rotation error {s['rotation_deg']['median']:.2f} > {rot}")
        if s["translation_frac"]["median"] > trans: bad.append(f"median translation error {s['translation_frac']['median']:.3f} > {trans}")
        if s["expression_rms_seen"]["median"] > expr: bad.append(f"median expression RMS {s['expression_rms_seen']['median']:.3f} > {expr}")
        if s["mask_iou"]["median"] < iou: bad.append(f"median mask IoU {s['mask_iou']['median']:.3f} < {iou}")
        if bad:
            print("track_eval: " + "; ".join(bad), file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
