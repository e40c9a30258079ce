#!/usr/bin/env bash
# scripts/expr_gain_by_expression.py on a known answer: two hand-made eval directories whose frames'
# scores and expressions are chosen, pooled; every group's frame count and means are checked, and a
# metrics.json frame the dataset lacks is an error that names it.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
SCRIPT="$HERE/../../scripts/expr_gain_by_expression.py"

/usr/bin/python3 - "$TMP" <<'PY'
import json, os, sys
tmp = sys.argv[1]
names = ["jaw_open", "eye_close_left", "eye_close_right"]
# (expression, expr_gain, expr_gain_coarse); None: a frame with negligible change (no score)
sets = {
    "a": [([0.5, 0.0, 0.0], 0.9, 1.0), ([0.0, 0.3, 0.0], 0.4, 0.6), ([0.0, 0.0, 0.0], None, None)],
    "b": [([0.3, 0.0, 0.6], 0.6, 0.8), ([0.1, 0.2, 0.0], 0.7, 0.9)],
}
for key, frames in sets.items():
    os.makedirs(f"{tmp}/e{key}"); os.makedirs(f"{tmp}/d{key}")
    test = {"expression_names": names, "frames": []}
    metrics = {"frames": []}
    for i, (beta, gain, coarse) in enumerate(frames):
        path = f"images/test_{i:03d}.png"
        test["frames"].append({"file_path": path, "expression": beta})
        metrics["frames"].append({"file_path": path, "tier": "near", "expr_gain": gain, "expr_gain_coarse": coarse})
    json.dump(test, open(f"{tmp}/d{key}/transforms_test.json", "w"))
    json.dump(metrics, open(f"{tmp}/e{key}/metrics.json", "w"))
PY
/usr/bin/python3 "$SCRIPT" "$TMP/ea=$TMP/da" "$TMP/eb=$TMP/db" --json "$TMP/out.json" >/dev/null || fail "the script failed"
/usr/bin/python3 - "$TMP/out.json" <<'PY'
import json, sys
g = json.load(open(sys.argv[1]))["groups"]
def check(name, n, gain, coarse):
    assert g[name]["frames"] == n, (name, g[name])
    assert abs(g[name]["expr_gain"] - gain) < 1e-12 and abs(g[name]["expr_gain_coarse"] - coarse) < 1e-12, (name, g[name])
check("all", 4, (0.9 + 0.4 + 0.6 + 0.7) / 4, (1.0 + 0.6 + 0.8 + 0.9) / 4)
check("eye closure", 2, (0.4 + 0.6) / 2, (0.6 + 0.8) / 2)        # 0.2 is below the 0.25 threshold
check("no eye closure", 2, (0.9 + 0.7) / 2, (1.0 + 0.9) / 2)
check("jaw_open", 2, (0.9 + 0.6) / 2, (1.0 + 0.8) / 2)
check("eye_close_right", 1, 0.6, 0.8)
assert "eye_close_left" in g and g["eye_close_left"]["frames"] == 1
PY
# A frame the dataset does not have: one clear line naming it, non-zero exit.
if /usr/bin/python3 "$SCRIPT" "$TMP/ea=$TMP/db" 2>"$TMP/err" >/dev/null; then fail "accepted a mismatched dataset"; fi
grep -q "no frame images/test_002.png" "$TMP/err" || fail "unclear error: $(cat "$TMP/err")"
if /usr/bin/python3 "$SCRIPT" "$TMP/missing=$TMP/da" 2>"$TMP/err" >/dev/null; then fail "accepted a missing eval directory"; fi
grep -q "missing/metrics.json: cannot read" "$TMP/err" || fail "unclear error: $(cat "$TMP/err")"
echo "expr_gain_by_expression_test: OK"
