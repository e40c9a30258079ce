#!/usr/bin/env bash
# scripts/expr_gain_probe.py on known answers: "renders" that are the ground truth itself reproduce
# all of every expression at every scale (expr_gain 1), "renders" that are the neutral reproduce none
# (0), and the blurred truth scores well below 1 on pixels and close to 1 after the low-pass.
set -euo pipefail
ICEF="$1"
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$ICEF" synth --identity-seed 101 --k 3 --res 96 --test-views 1 --novel-per-tier 1 --out "$TMP/d" >/dev/null
mkdir -p "$TMP/truth/renders" "$TMP/neutral/renders"
for f in "$TMP"/d/images/test_*.png; do
  b=$(basename "$f")
  case "$b" in
    test_neutral_*) cp "$f" "$TMP/truth/renders/${b/test_neutral/neutral}"; cp "$f" "$TMP/neutral/renders/${b/test_neutral/neutral}" ;;
    *) cp "$f" "$TMP/truth/renders/$b" ;;
  esac
done
# The neutral "renders": each test frame rendered as its view's neutral.
/usr/bin/python3 - "$TMP" <<'PY'
import json, shutil, sys, os
tmp = sys.argv[1]
for f in json.load(open(f"{tmp}/d/transforms_test.json"))["frames"]:
    shutil.copy(os.path.join(tmp, "d", f["neutral_file_path"]), os.path.join(tmp, "neutral/renders", os.path.basename(f["file_path"])))
PY
PROBE="$HERE/../../scripts/expr_gain_probe.py"
/usr/bin/python3 "$PROBE" "$TMP/d" "$TMP/truth" --json "$TMP/truth.json" >/dev/null || fail "probe on the truth"
/usr/bin/python3 "$PROBE" "$TMP/d" "$TMP/neutral" --truth-blur "" --json "$TMP/neutral.json" >/dev/null || fail "probe on the neutral"
/usr/bin/python3 - "$TMP" <<'PY'
import json, sys
tmp = sys.argv[1]
truth = json.load(open(f"{tmp}/truth.json"))["expr_gain"]
neutral = json.load(open(f"{tmp}/neutral.json"))["expr_gain"]
assert truth["render"], "no tier measured"
for tier, gains in truth["render"].items():
    assert all(abs(g - 1) < 1e-6 for g in gains), (tier, gains)
for tier, gains in neutral["render"].items():
    assert all(abs(g) < 1e-9 for g in gains), (tier, gains)
for tier, gains in truth["blurred truth 1"].items():
    assert gains[0] < 0.7 and gains[2] > 0.8, (tier, gains)
print("expr_gain_probe_test: OK")
PY
