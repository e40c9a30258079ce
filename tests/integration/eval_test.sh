#!/usr/bin/env bash
# icef eval end to end: a tiny synthetic dataset, a tiny model trained for a few steps with
# `icef train`, evaluated; checks metrics.json (schema, tiers, nulls for LPIPS), the renders, the
# printed table, and that errors (missing model, bad LPIPS file) exit 1 naming the file.
set -euo pipefail
ICEF="$1"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$ICEF" synth --out "$WORK/data" --identity-seed 2 --k 3 --res 32 --test-views 1 --novel-per-tier 1 \
  --supersample 1 --threads 2 > /dev/null
TINY=(--set model.static_field.grid.num_levels=4 --set model.static_field.grid.log2_table_size=10 --set model.static_field.grid.finest_resolution=32
      --set model.static_field.density_hidden=16 --set "model.static_field.color_hidden=[16]" --set "model.deformation.hidden=[16,16]"
      --set model.sampler.num_samples=16 --set model.occupancy.resolution=16 --set train.batch_rays=256)
"$ICEF" train "$WORK/data" --out "$WORK/model" --steps 10 --threads 2 --quiet "${TINY[@]}" > "$WORK/train.txt" \
  || fail "icef train exited $?"
# The symmetry prior (on by default) reports how well the synthetic face's landmarks mirror.
grep -Eq "^symmetry prior: landmark pairs mirror onto each other within 0\.0[0-9]* inter-ocular distances$" \
  "$WORK/train.txt" || fail "no symmetry-plane line: $(cat "$WORK/train.txt")"

"$ICEF" eval "$WORK/model" "$WORK/data" --out "$WORK/eval" --threads 2 > "$WORK/out.txt" 2> "$WORK/err.txt" \
  || fail "icef eval exited $?: $(cat "$WORK/err.txt")"
cat "$WORK/out.txt"
grep -q "^method icef-prior, 6 test frames" "$WORK/out.txt" || fail "no summary line"
grep -Eq "^observed +3 " "$WORK/out.txt" || fail "table lacks the observed tier with 3 frames"
grep -Eq "^far +1 " "$WORK/out.txt" || fail "table lacks the far tier"
grep -q "lpips: unavailable" "$WORK/out.txt" || fail "LPIPS not reported as unavailable"
test -s "$WORK/eval/metrics.json" || fail "no metrics.json"
[ "$(ls "$WORK/eval/renders" | grep -c '^test_.*\.png$')" = 6 ] || fail "expected 6 renders"
test -s "$WORK/eval/renders/neutral_000.png" || fail "no neutral render"
[ "$(ls "$WORK/eval/renders" | grep -c '^fit_train_[0-9]*\.png$')" = 3 ] || fail "expected 3 training-view renders"
[ "$(ls "$WORK/eval/renders" | grep -c '^fit_train_[0-9]*_vs_truth\.png$')" = 3 ] \
  || fail "expected 3 training views beside their truth"
grep -Eq "^training-view fit: face-region PSNR [0-9.]+ dB \(worst [0-9.]+, 3 views\), full image [0-9.]+ dB, face detail [0-9.]+ x the truth's$" \
  "$WORK/out.txt" || fail "no training-view fit line"

# Schema: every frame and tier key present; LPIPS null; PSNR/SSIM numbers; identity numbers
# whenever the face-identity model is installed (the dataset has landmarks).
python3 - "$WORK/eval/metrics.json" <<'PY' || fail "metrics.json schema"
import json, math, os, sys
m = json.load(open(sys.argv[1]))
assert m["method"] == "icef-prior"
assert len(m["frames"]) == 6
for f in m["frames"]:
    for k in ["file_path", "tier", "delta", "psnr", "ssim", "lpips", "id_cosine", "id_distance", "id_distance_gt",
              "id_distance_reference", "id_excess", "expr_gain", "expr_corr", "expr_true_rms", "region_psnr",
              "psnr_neutral_floor"]:
        assert k in f, k
    assert isinstance(f["region_psnr"], float) and isinstance(f["psnr_neutral_floor"], float)
    assert f["lpips"] is None
    assert isinstance(f["psnr"], float) and isinstance(f["ssim"], float)
    if m["identity_available"]:
        assert f["id_distance_gt"] is not None
counts = {t: m["tiers"][t]["count"] for t in ["observed", "near", "moderate", "far"]}
assert counts == {"observed": 3, "near": 1, "moderate": 1, "far": 1}, counts
for t, v in m["tiers"].items():
    for k in ["count", "psnr", "ssim", "lpips", "id_cosine", "id_distance", "id_distance_gt", "id_share_under_0_6",
              "id_excess", "expr_gain", "expr_corr", "region_psnr", "psnr_neutral_floor", "expr_count",
              "expr_negligible"]:
        assert k in v, (t, k)
    assert v["expr_count"] + v["expr_negligible"] == v["count"], (t, v)
    frames = [f for f in m["frames"] if f["tier"] == t]
    assert abs(v["psnr"] - sum(f["psnr"] for f in frames) / len(frames)) < 1e-9
    assert v["lpips"] is None
fit = m["train_fit"]
assert fit["count"] == 3 and fit["face_count"] == 3 and len(fit["frames"]) == 3, fit
for f in fit["frames"]:
    assert isinstance(f["face_psnr"], float) and isinstance(f["psnr"], float) and f["face_pixels"] > 0, f
    assert os.path.exists(os.path.join(os.path.dirname(sys.argv[1]), f["render"])), f
assert abs(fit["face_psnr"] - sum(f["face_psnr"] for f in fit["frames"]) / 3) < 1e-9
assert fit["face_psnr_min"] == min(f["face_psnr"] for f in fit["frames"])
print("metrics.json ok; identity available:", m["identity_available"])
PY

# A model that renders no expression (--expression-scale 0): expr_gain exactly 0 wherever measured.
"$ICEF" eval "$WORK/model" "$WORK/data" --out "$WORK/still" --expression-scale 0 --threads 2 > "$WORK/still.txt" \
  || fail "icef eval --expression-scale 0 exited $?"
grep -q "every frame rendered at 0 x its expression" "$WORK/still.txt" || fail "no expression-scale line"
python3 - "$WORK/still/metrics.json" <<'PY' || fail "--expression-scale 0 did not give expr_gain 0"
import json, sys
m = json.load(open(sys.argv[1]))
assert m["expression_scale"] == 0
gains = [f["expr_gain"] for f in m["frames"] if f["expr_gain"] is not None]
assert gains and all(g == 0 for g in gains), gains
print("still model: expr_gain 0 on", len(gains), "frames")
PY
if "$ICEF" eval "$WORK/model" "$WORK/data" --out "$WORK/e4" --expression-scale nan 2> "$WORK/err.txt"; then
  fail "--expression-scale nan accepted"
fi
grep -q "expression" "$WORK/err.txt" || fail "NaN scale error does not name the option: $(cat "$WORK/err.txt")"

# Errors: a missing model, an unreadable LPIPS weights file.
if "$ICEF" eval "$WORK/none" "$WORK/data" --out "$WORK/e2" 2> "$WORK/err.txt"; then fail "missing model accepted"; fi
grep -q "none" "$WORK/err.txt" || fail "error does not name the model: $(cat "$WORK/err.txt")"
echo "garbage" > "$WORK/bad.bin"
if "$ICEF" eval "$WORK/model" "$WORK/data" --out "$WORK/e3" --lpips-weights "$WORK/bad.bin" 2> "$WORK/err.txt"; then
  fail "bad LPIPS weights accepted"
fi
grep -q "bad.bin" "$WORK/err.txt" || fail "error does not name the weights file: $(cat "$WORK/err.txt")"
echo "eval_test: OK"
