#!/usr/bin/env bash
# scripts/expr_gain_sharpness.py on a known answer: a hand-made dataset whose true change is an edge
# that moves inside the landmark region (and a change outside it, which must not count), with one
# render equal to the truth and one equal to the truth blurred by 0.5 px. Checks the truth's own
# score (1 unblurred, lower blurred), the recovered softness of each render, the recomputed
# expr_gain against eval's, and that bad input is one clear line and a non-zero exit.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
SCRIPT="$HERE/../../scripts/expr_gain_sharpness.py"

/usr/bin/python3 - "$TMP" "$SCRIPT" <<'PY'
import importlib.util, json, os, sys
import numpy as np
from PIL import Image
tmp, script = sys.argv[1], sys.argv[2]
spec = importlib.util.spec_from_file_location("sharp", script)
sharp = importlib.util.module_from_spec(spec); spec.loader.exec_module(sharp)
os.makedirs(f"{tmp}/d/images"); os.makedirs(f"{tmp}/e/renders")
n = 64
y, x = np.mgrid[0:n, 0:n]
def face(bar):
    img = np.stack([0.6 + 0.002 * x, 0.5 + 0.001 * y, 0.4 + 0 * x], 2)
    img[(x >= bar) & (x < bar + 6) & (y >= 24) & (y < 40)] = [0.1, 0.05, 0.05]
    return img
neutral, expressed = face(28), face(30)
expressed[2:6, 2:6] = 0.0  # a change outside the region: not the expression
def save(path, img):
    Image.fromarray(np.clip(np.round(img * 255), 0, 255).astype(np.uint8)).save(path)
    return np.asarray(Image.open(path), dtype=np.float64) / 255.0
neutral = save(f"{tmp}/d/images/test_neutral_000.png", neutral)
save(f"{tmp}/d/images/test_neutral_001.png", neutral)
expressed = save(f"{tmp}/d/images/test_000.png", expressed)
save(f"{tmp}/d/images/test_001.png", expressed)
sharp_render = save(f"{tmp}/e/renders/test_000.png", expressed)
soft_render = save(f"{tmp}/e/renders/test_001.png", sharp.gaussian_blur(expressed, 0.5))
save(f"{tmp}/e/renders/neutral_000.png", neutral)
soft_neutral = save(f"{tmp}/e/renders/neutral_001.png", sharp.gaussian_blur(neutral, 0.5))
landmarks = [[1.0, 1.0]] * 68
for i in list(range(17, 27)) + list(range(36, 68)):
    landmarks[i] = [[16.0, 16.0], [48.0, 16.0], [48.0, 48.0], [16.0, 48.0]][i % 4]
frames, scored = [], []
for i, tier in enumerate(["near", "far"]):
    frames.append({"file_path": f"images/test_{i:03d}.png", "neutral_file_path": f"images/test_neutral_{i:03d}.png",
                   "tier": tier, "landmarks_2d": landmarks, "neutral_landmarks_2d": landmarks})
mask = sharp.region_mask(n, n, [landmarks], sharp.REGION_LANDMARKS, 1)
truth_change = (expressed - neutral) * mask
gains = [1.0, sharp.gain((soft_render - soft_neutral) * mask, truth_change)]
for i, g in enumerate(gains):
    scored.append({"file_path": f"images/test_{i:03d}.png", "render": f"renders/test_{i:03d}.png", "expr_gain": g})
json.dump({"frames": frames}, open(f"{tmp}/d/transforms_test.json", "w"))
json.dump({"frames": []}, open(f"{tmp}/d/transforms_train.json", "w"))
json.dump({"frames": scored}, open(f"{tmp}/e/metrics.json", "w"))
PY
/usr/bin/python3 "$SCRIPT" "$TMP/e=$TMP/d" --sigmas 0,0.5 --json "$TMP/out.json" >/dev/null || fail "the script failed"
/usr/bin/python3 - "$TMP/out.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
near, far = r["tiers"]["near"], r["tiers"]["far"]
assert near["frames"] == 1 and far["frames"] == 1, r
assert abs(near["truth_blurred"]["0"] - 1.0) < 1e-12, near        # the truth reproduces all of itself
assert 0.3 < near["truth_blurred"]["0.5"] < 0.95, near            # and less of it when soft
assert near["render_sigma"] == 0.0, near                          # the render is the truth
assert abs(far["render_sigma"] - 0.5) <= 0.051, far               # the render is the truth at 0.5 px
assert abs(far["expr_gain"] - far["truth_blurred"]["0.5"]) < 0.02, far
assert r["mean_gain_mismatch"] < 1e-9, r                          # the change outside the region does not count
assert r["train_sigma"] is None, r
PY
# Bad input: one clear line naming what is wrong, non-zero exit.
rm "$TMP/e/renders/neutral_000.png"
if /usr/bin/python3 "$SCRIPT" "$TMP/e=$TMP/d" 2>"$TMP/err" >/dev/null; then fail "accepted a missing neutral render"; fi
grep -q "neutral_000.png" "$TMP/err" || fail "unclear error: $(cat "$TMP/err")"
if /usr/bin/python3 "$SCRIPT" "$TMP/e" 2>"$TMP/err" >/dev/null; then fail "accepted a pair without ="; fi
grep -q "expected EVAL_DIR=DATASET" "$TMP/err" || fail "unclear error: $(cat "$TMP/err")"
echo "expr_gain_sharpness_test: OK"
