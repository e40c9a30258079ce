#!/usr/bin/python3
"""The expression style `icef train` fitted (its log's `face fit:` line) against the synthetic
identity's true style (the dataset's style.json), for the style's fields that the training frames'
expressions use (a field no training frame uses keeps the generic value by construction).

usage: style_recovery.py TRAIN_LOG=DATASET ... [--json OUT]
"""
import json
import re
import sys

FIELD_EXPRESSIONS = {
    "jaw_gain": ["jaw_open"], "jaw_hinge_dy": ["jaw_open"], "jaw_hinge_dz": ["jaw_open"],
    "smile_gain[0]": ["smile_right"], "smile_gain[1]": ["smile_left"],
    "smile_width": ["smile_left", "smile_right"], "smile_lift": ["smile_left", "smile_right"],
    "smile_corner_shift": ["smile_left", "smile_right"],
    "lip_pucker_gain": ["lip_pucker"], "lip_press_gain": ["lip_press"],
    "brow_raise_gain[0]": ["brow_raise_right"], "brow_raise_gain[1]": ["brow_raise_left"],
    "brow_raise_shift": ["brow_raise_left", "brow_raise_right"], "brow_furrow_gain": ["brow_furrow"],
    "eye_close_gain[0]": ["eye_close_right"], "eye_close_gain[1]": ["eye_close_left"],
    "cheek_puff_gain": ["cheek_puff"],
}
GENERIC = {k: (0.0 if ("shift" in k or "hinge" in k) else 1.0) for k in FIELD_EXPRESSIONS}


def flat_truth(style):
    out = {}
    for k, v in style.items():
        if isinstance(v, list):
            for i, x in enumerate(v):
                out[f"{k}[{i}]"] = x
        else:
            out[k] = v
    return out


def fitted_style(log_path):
    for line in open(log_path):
        if line.startswith("face fit:"):
            fitted = dict(GENERIC)
            if "expression style:" in line:
                for name, value in re.findall(r"([a-z_]+(?:\[\d\])?) (-?[0-9.e-]+)", line.split("expression style:")[1]):
                    fitted[name] = float(value)
            return fitted
    sys.exit(f"{log_path}: no 'face fit:' line")


def main(argv):
    out_path = None
    if "--json" in argv:
        i = argv.index("--json")
        out_path = argv[i + 1]
        argv = argv[:i] + argv[i + 2:]
    rows = []
    for pair in argv:
        log, dataset = pair.split("=")
        truth_doc = json.load(open(f"{dataset}/style.json"))
        truth = flat_truth(truth_doc["style"])
        train = json.load(open(f"{dataset}/transforms_train.json"))
        names = train["expression_names"]
        used = {n for f in train["frames"] for n, w in zip(names, f["expression"]) if w > 0}
        fitted = fitted_style(log)
        for field, exprs in FIELD_EXPRESSIONS.items():
            if not used.intersection(exprs):
                continue
            rows.append({"seed": truth_doc["identity_seed"], "field": field, "true": truth[field],
                         "fitted": fitted[field], "generic_error": abs(truth[field] - GENERIC[field]),
                         "fitted_error": abs(truth[field] - fitted[field])})
    summary = {}
    for kind, pred in (("gains", lambda f: not ("shift" in f or "hinge" in f)), ("offsets", lambda f: "shift" in f or "hinge" in f)):
        sel = [r for r in rows if pred(r["field"])]
        if sel:
            summary[kind] = {"fields": len(sel),
                             "mean_generic_error": sum(r["generic_error"] for r in sel) / len(sel),
                             "mean_fitted_error": sum(r["fitted_error"] for r in sel) / len(sel),
                             "fitted_closer": sum(r["fitted_error"] < r["generic_error"] for r in sel)}
    for kind, s in summary.items():
        print(f"{kind}: {s['fields']} fields the training frames use; mean |error| generic {s['mean_generic_error']:.3f}, "
              f"fitted {s['mean_fitted_error']:.3f}; fitted closer in {s['fitted_closer']}")
    if out_path:
        with open(out_path, "w") as f:
            json.dump({"summary": summary, "fields": rows}, f, indent=1)


if __name__ == "__main__":
    main(sys.argv[1:])
