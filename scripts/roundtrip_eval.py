#!/usr/bin/python3
"""The `icef track --keep-cameras` round trip, on synthetic datasets with known expressions.

For each identity seed: `icef synth` renders the procedural head (in the identity's own expression
style) as a training dataset with its test tiers; `icef track DATASET --keep-cameras` re-expresses
it in the face model's expression space; this script compares the tracked weights with the true
ones, per split and per weight:

- `rms`: RMS over frames and the 11 weights of (tracked - true);
- `rms_vs_styled`: the same against the true weight times the identity's own gain for that
  expression (style.json; e.g. a jaw gain of 0.7 opens the jaw 0.7 times as far per unit): what a
  tracker that knows only the face model's generic style could read at best, if the style only
  scaled the expressions (it also moves where they act);
- `per_weight`: the RMS of each weight, both ways;
- the fitted head_from_world similarity's scale and rotation against the synthetic scene's
  placement (scene.json; the world frame is the head frame scaled and offset by it).

With --train-steps S it then trains `icef-prior` (S steps, one thread) on the original and on the
tracked dataset and evaluates both on their test frames (`icef eval --threads 1`): PSNR and
`expr_gain` per tier, the criterion of the tracker issue being the tracked dataset within 1 dB and
0.1 of the original. --train-seeds 0,1,2 trains each dataset once per training seed
(`train.seed`; 0 is the default) and compares the means over them, each seed's scores kept in the
JSON (`original_runs`, `tracked_runs`): a near tier of six frames moves by a few hundredths from one
training seed to the next. --jobs N runs N trainings at once (each still on one thread).

Usage: scripts/roundtrip_eval.py --icef build/icef --out DIR [--seeds 101,102,103] [--res 128]
       [--track-args="--landmarks model"] [--train-steps 1000] [--train-seeds 0] [--jobs 1] [--reuse]
(--reuse: evaluate DIR's datasets as they are, without running icef synth/track again)
Writes DIR/roundtrip_eval.json and prints a table.
Tune on validation identities (seeds >= 101); the test identities are 1, 2, 3.
"""
import argparse
import concurrent.futures
import json
import math
import os
import shlex
import subprocess

import numpy as np

TIERS = ("observed", "near", "moderate", "far")

# Which ExpressionStyle gain multiplies each named expression (face/expression_style.cc,
# WeightGain); paired values are [right, left].
GAIN_OF = {
    "jaw_open": ("jaw_gain", None),
    "smile_left": ("smile_gain", 1),
    "smile_right": ("smile_gain", 0),
    "lip_pucker": ("lip_pucker_gain", None),
    "lip_press": ("lip_press_gain", None),
    "brow_raise_left": ("brow_raise_gain", 1),
    "brow_raise_right": ("brow_raise_gain", 0),
    "brow_furrow": ("brow_furrow_gain", None),
    "eye_close_left": ("eye_close_gain", 1),
    "eye_close_right": ("eye_close_gain", 0),
    "cheek_puff": ("cheek_puff_gain", None),
}


def run(cmd, log):
    with open(log, "w") as f:
        subprocess.run(cmd, check=True, stdout=f, stderr=subprocess.STDOUT)


def style_gains(style, names):
    gains = []
    for name in names:
        key, side = GAIN_OF[name]
        value = style[key]
        gains.append(float(value if side is None else value[side]))
    return np.asarray(gains)


def rotation_angle_deg(r):
    c = (np.trace(r) - 1) / 2
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def compare_split(orig, tracked, split, gains):
    a = json.load(open(os.path.join(orig, f"transforms_{split}.json")))
    b = json.load(open(os.path.join(tracked, f"transforms_{split}.json")))
    if a["expression_names"] != b["expression_names"]:
        raise SystemExit(f"{orig}: expression_names differ from the face model's; this script compares synthetic datasets")
    if len(a["frames"]) != len(b["frames"]):
        raise SystemExit(f"{tracked}/transforms_{split}.json: {len(b['frames'])} frames, the original has {len(a['frames'])}")
    true = np.asarray([f["expression"] for f in a["frames"]], dtype=float)
    got = np.asarray([f["expression"] for f in b["frames"]], dtype=float)
    err, err_styled = got - true, got - true * gains
    names = a["expression_names"]
    return {
        "frames": int(true.shape[0]),
        "rms": float(np.sqrt(np.mean(err**2))),
        "rms_vs_styled": float(np.sqrt(np.mean(err_styled**2))),
        "per_weight": {n: {"rms": float(np.sqrt(np.mean(err[:, i] ** 2))),
                           "rms_vs_styled": float(np.sqrt(np.mean(err_styled[:, i] ** 2))),
                           "true_mean": float(np.mean(true[:, i]))} for i, n in enumerate(names)},
    }


def similarity_error(orig, tracked):
    report = json.load(open(os.path.join(tracked, "track", "report.json")))
    sim = report["head_from_world"]
    placement = json.load(open(os.path.join(orig, "scene.json")))["placement"]
    # world = head_scale * head + head_offset, so the true head_from_world scale is 1 / head_scale.
    true_scale = 1.0 / float(placement["head_scale"])
    return {"scale": float(sim["scale"]), "scale_error": float(sim["scale"]) / true_scale - 1.0,
            "rotation_deg": rotation_angle_deg(np.asarray(sim["rotation"], dtype=float))}


def train_and_eval(icef, dataset, work, steps, train_seed=0):
    # Seed 0 keeps the directory names of runs made before --train-seeds, so --reuse finds them.
    if train_seed != 0:
        work = f"{work}_seed{train_seed}"
    model, evaluation = work + "_model", work + "_eval"
    if not os.path.exists(os.path.join(evaluation, "metrics.json")):
        subprocess.run(["rm", "-rf", model, evaluation], check=True)
        run([icef, "train", dataset, "--out", model, "--method", "icef-prior", "--steps", str(steps),
             "--time-budget", "0", "--threads", "1", "--set", f"train.seed={train_seed}"], work + "_train.log")
        run([icef, "eval", model, dataset, "--out", evaluation, "--threads", "1"], work + "_eval.log")
    metrics = json.load(open(os.path.join(evaluation, "metrics.json")))
    tiers = metrics["tiers"]
    return {t: {"psnr": tiers[t]["psnr"], "expr_gain": tiers[t].get("expr_gain")} for t in TIERS if t in tiers}


def mean_scores(runs):
    """Per tier, the mean PSNR and expr_gain over training runs."""
    out = {}
    for t in TIERS:
        have = [r[t] for r in runs if t in r]
        if not have:
            continue
        gains = [h["expr_gain"] for h in have if h["expr_gain"] is not None]
        out[t] = {"psnr": float(np.mean([h["psnr"] for h in have])),
                  "expr_gain": float(np.mean(gains)) if gains else None}
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--icef", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--seeds", default="101,102,103")
    p.add_argument("--res", type=int, default=128)
    p.add_argument("--track-args", default="", help="extra arguments for icef track (one string)")
    p.add_argument("--train-steps", type=int, default=0, help="also train icef-prior on both datasets and compare")
    p.add_argument("--train-seeds", default="0", help="training seeds (train.seed) per dataset; the means are compared")
    p.add_argument("--jobs", type=int, default=1, help="trainings run at once (one thread each)")
    p.add_argument("--reuse", action="store_true")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    seeds = [int(s) for s in args.seeds.split(",")]
    rows = []
    for seed in seeds:
        orig = os.path.join(args.out, f"orig_{seed}")
        tracked = os.path.join(args.out, f"track_{seed}")
        if not args.reuse:
            if not os.path.exists(os.path.join(orig, "transforms_train.json")):
                subprocess.run(["rm", "-rf", orig], check=True)
                run([args.icef, "synth", "--identity-seed", str(seed), "--res", str(args.res), "--out", orig],
                    orig + "_synth.log")
            subprocess.run(["rm", "-rf", tracked], check=True)
            run([args.icef, "track", orig, "--keep-cameras", "--out", tracked] + shlex.split(args.track_args),
                tracked + "_track.log")
        style = json.load(open(os.path.join(orig, "style.json")))["style"]
        names = json.load(open(os.path.join(orig, "transforms_train.json")))["expression_names"]
        gains = style_gains(style, names)
        row = {"seed": seed, "role": "validation" if seed >= 101 else "test",
               "similarity": similarity_error(orig, tracked),
               "expressions": {s: compare_split(orig, tracked, s, gains) for s in ("train", "test")}}
        rows.append(row)

    if args.train_steps > 0:
        train_seeds = [int(s) for s in args.train_seeds.split(",")]
        jobs = {}
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            for row in rows:
                for label, name in (("original", "orig"), ("tracked", "track")):
                    path = os.path.join(args.out, f"{name}_{row['seed']}")
                    for ts in train_seeds:
                        jobs[(row["seed"], label, ts)] = pool.submit(train_and_eval, args.icef, path, path,
                                                                      args.train_steps, ts)
        for row in rows:
            for label in ("original", "tracked"):
                runs = {ts: jobs[(row["seed"], label, ts)].result() for ts in train_seeds}
                row[label] = mean_scores(list(runs.values()))
                if len(train_seeds) > 1:
                    row[f"{label}_runs"] = {str(ts): r for ts, r in runs.items()}
            row["train_seeds"] = train_seeds

    summary = {}
    for split in ("train", "test"):
        summary[f"{split}_rms_mean"] = float(np.mean([r["expressions"][split]["rms"] for r in rows]))
        summary[f"{split}_rms_vs_styled_mean"] = float(np.mean([r["expressions"][split]["rms_vs_styled"] for r in rows]))
    doc = {"seeds": seeds, "res": args.res, "track_args": args.track_args, "train_steps": args.train_steps,
           "train_seeds": [int(s) for s in args.train_seeds.split(",")] if args.train_steps > 0 else [],
           "summary": summary, "rows": rows}
    path = os.path.join(args.out, "roundtrip_eval.json")
    with open(path + ".tmp", "w") as f:
        json.dump(doc, f, indent=1)
    os.replace(path + ".tmp", path)

    print(f"{'seed':>5} {'scale err':>9} {'rot deg':>7} | {'train rms':>9} {'styled':>6} | {'test rms':>8} {'styled':>6}")
    for r in rows:
        e = r["expressions"]
        print(f"{r['seed']:>5} {r['similarity']['scale_error']:>9.4f} {r['similarity']['rotation_deg']:>7.2f} | "
              f"{e['train']['rms']:>9.3f} {e['train']['rms_vs_styled']:>6.3f} | {e['test']['rms']:>8.3f} {e['test']['rms_vs_styled']:>6.3f}")
        if "tracked" in r:
            for label in ("original", "tracked"):
                t = r[label]
                print(f"      {label:>9} PSNR " + " / ".join(f"{t[k]['psnr']:.2f}" for k in TIERS if k in t) +
                      "   expr_gain " + " / ".join(f"{t[k]['expr_gain']:.3f}" for k in TIERS if k in t))
            o, t = r["original"], r["tracked"]
            both = [k for k in TIERS if k in o and k in t]
            print(f"      {'difference':>9} PSNR " + " / ".join(f"{t[k]['psnr'] - o[k]['psnr']:+.2f}" for k in both) +
                  "   expr_gain " + " / ".join(f"{t[k]['expr_gain'] - o[k]['expr_gain']:+.3f}" for k in both) +
                  f"   (mean over training seeds {r['train_seeds']})")
    names = list(rows[0]["expressions"]["train"]["per_weight"].keys())
    print("per weight, RMS over all seeds' train / test frames:")
    for n in names:
        cells = []
        for split in ("train", "test"):
            sq = [r["expressions"][split]["per_weight"][n]["rms"] ** 2 * r["expressions"][split]["frames"] for r in rows]
            count = sum(r["expressions"][split]["frames"] for r in rows)
            cells.append(math.sqrt(sum(sq) / count))
        print(f"  {n:>17}: {cells[0]:.3f} / {cells[1]:.3f}")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
