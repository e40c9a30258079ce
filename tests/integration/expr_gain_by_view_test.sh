#!/usr/bin/env bash
# scripts/expr_gain_by_view.py on a known answer: two hand-made eval directories whose test cameras,
# training cameras and per-frame scores are chosen; the groups by true change, the within-run
# differences (farther view, larger change, elevation outside the training range) and the tiers'
# separation are checked, and bad input is an error that names the file and the field.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
SCRIPT="$HERE/../../scripts/expr_gain_by_view.py"

/usr/bin/python3 - "$TMP" <<'PY'
import json, math, os, sys
tmp = sys.argv[1]
def cam(yaw, pitch, r=4.0):  # camera position at this yaw / elevation (degrees) about the origin
    y, p = math.radians(yaw), math.radians(pitch)
    return [[1, 0, 0, r * math.sin(y) * math.cos(p)], [0, 1, 0, r * math.sin(p)], [0, 0, 1, r * math.cos(y) * math.cos(p)], [0, 0, 0, 1]]
aabb = [[-1, -1, -1], [1, 1, 1]]
train = [cam(0, 0), cam(0, 10)]  # training elevations 0-10 degrees
# (camera, tier, expr_gain, expr_corr, expr_gain_coarse, expr_true_rms); None: negligible change
sets = {
    "a": [(cam(0, 5), "near", 0.9, 0.9, 0.95, 0.05),    # 5 deg from both, inside
          (cam(0, -10), "near", 0.5, 0.625, 0.7, 0.01),  # 10 deg from the first, elevation outside
          (cam(20, 0), "near", 0.7, 0.7, 0.8, 0.03),     # 20 deg from the first, inside
          (cam(0, 5), "near", None, None, None, 0.002)],
    "b": [(cam(0, 5), "near", 0.6, 0.75, 0.9, 0.04), (cam(0, 5), "far", 0.3, 0.6, 0.5, 0.08)],
}
for key, frames in sets.items():
    os.makedirs(f"{tmp}/e{key}"); os.makedirs(f"{tmp}/d{key}")
    json.dump({"aabb": aabb, "frames": [{"file_path": f"images/train_{i:03d}.png", "transform_matrix": m} for i, m in enumerate(train)]},
              open(f"{tmp}/d{key}/transforms_train.json", "w"))
    test = {"aabb": aabb, "frames": []}
    metrics = {"frames": []}
    for i, (m, tier, gain, corr, coarse, rms) in enumerate(frames):
        path = f"images/test_{i:03d}.png"
        test["frames"].append({"file_path": path, "transform_matrix": m})
        metrics["frames"].append({"file_path": path, "tier": tier, "expr_gain": gain, "expr_corr": corr,
                                  "expr_gain_coarse": coarse, "expr_true_rms": rms})
    json.dump(test, open(f"{tmp}/d{key}/transforms_test.json", "w"))
    json.dump(metrics, open(f"{tmp}/e{key}/metrics.json", "w"))
PY
/usr/bin/python3 "$SCRIPT" "$TMP/ea=$TMP/da" "$TMP/eb=$TMP/db" --tiers near,far --change-groups 2 --json "$TMP/out.json" >/dev/null ||
  fail "the script failed"
/usr/bin/python3 - "$TMP/out.json" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["tiers"]
near, far = t["near"], t["far"]
close = lambda a, b: abs(a - b) < 1e-9
a = near["all"]
assert a["frames"] == 4, a
assert close(a["expr_gain"], (0.9 + 0.5 + 0.7 + 0.6) / 4) and close(a["expr_corr"], (0.9 + 0.625 + 0.7 + 0.75) / 4), a
assert close(a["ratio"], (1 + 0.8 + 1 + 0.8) / 4) and close(a["expr_gain_coarse"], (0.95 + 0.7 + 0.8 + 0.9) / 4), a
groups = list(near["by_change"].values())  # by true RMS: 0.01 and 0.03, then 0.04 and 0.05
assert [g["frames"] for g in groups] == [2, 2], groups
assert close(groups[0]["expr_gain"], 0.6) and close(groups[1]["expr_gain"], 0.75), groups
w = near["within_runs"]  # run a alone: run b has one near frame
assert all(v["runs"] == 1 for v in w.values()), w
assert close(w["larger true change"]["mean_gain_difference"], (0.7 + 0.9) / 2 - 0.5), w
assert close(w["farther view"]["mean_gain_difference"], (0.5 + 0.7) / 2 - 0.9), w
assert close(w["elevation outside the training range"]["mean_gain_difference"], 0.5 - (0.9 + 0.7) / 2), w
assert far["all"]["frames"] == 1 and close(far["all"]["expr_gain"], 0.3) and far["within_runs"] == {}, far
PY
# Bad input: one clear line naming the file and the field, non-zero exit.
if /usr/bin/python3 "$SCRIPT" "$TMP/ea=$TMP/db" --tiers near 2>"$TMP/err" >/dev/null; then fail "accepted a mismatched dataset"; fi
grep -q "no frame images/test_002.png" "$TMP/err" || fail "unclear error: $(cat "$TMP/err")"
sed -i 's/"transform_matrix": \[\[1, 0, 0, 0.0/"transform_matrix": [[1/' "$TMP/da/transforms_train.json"
if /usr/bin/python3 "$SCRIPT" "$TMP/ea=$TMP/da" --tiers near 2>"$TMP/err" >/dev/null; then fail "accepted a broken transform_matrix"; fi
grep -q "da/transforms_train.json: images/train_000.png: transform_matrix" "$TMP/err" || fail "unclear error: $(cat "$TMP/err")"
if /usr/bin/python3 "$SCRIPT" "$TMP/missing=$TMP/db" --tiers near 2>"$TMP/err" >/dev/null; then fail "accepted a missing eval directory"; fi
grep -q "missing/metrics.json: cannot read" "$TMP/err" || fail "unclear error: $(cat "$TMP/err")"
[ ! -e "$HERE/../../scripts/__pycache__" ] || fail "the script wrote scripts/__pycache__"
echo "expr_gain_by_view_test: OK"
