#!/usr/bin/env bash
# `icef demo --quick`: the whole pipeline (synthesise, train, turntable, sweeps) on tiny settings
# leaves the files it promises and prints where they are.
set -euo pipefail
ICEF="$1"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
"$ICEF" demo --quick --out "$TMP/demo" --threads 2 > "$TMP/log"
for f in data/transforms_train.json model/checkpoint.icef model/summary.json model/train_log.jsonl \
         turntable/color.gif turntable/color_000.png turntable/depth_000.png turntable/frames.json \
         sweep_jaw_open/color.gif sweep_smile_left/frames.json sweep_brow_raise_right/mask_000.png \
         sweep_jaw_open/compare.gif sweep_smile_left/compare_002.png; do
  [ -s "$TMP/demo/$f" ] || { echo "demo did not write $f" >&2; cat "$TMP/log" >&2; exit 1; }
done
grep -q "ICEF demo finished" "$TMP/log"
grep -q "turntable/color.gif" "$TMP/log"
# The sweeps go past the training expressions: kappa falls below 1 by the last frame.
python3 - "$TMP/demo/sweep_jaw_open/frames.json" <<'PY'
import json, sys
frames = json.load(open(sys.argv[1]))["frames"]
assert frames[-1]["kappa"] < 1.0 and frames[-1]["delta"] > 0, frames[-1]
PY
echo "demo_test: ok"
