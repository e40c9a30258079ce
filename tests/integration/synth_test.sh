#!/usr/bin/env bash
# icef synth end to end: a tiny dataset, read back by `icef info`, rendered twice to the same
# bytes, the face model fitted to it (icef mask), a contact sheet from `icef sheet`, and a bad
# option rejected with exit code 1.
set -euo pipefail
ICEF="$1"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT

"$ICEF" synth --out "$WORK/a" --identity-seed 3 --k 3 --res 32 --test-views 2 --novel-per-tier 1 \
  --threads 2 --contact-sheet "$WORK/sheet_a.png" > "$WORK/log.txt"
grep -q "wrote $WORK/a: 3 train + 12 test frames" "$WORK/log.txt"
test -s "$WORK/sheet_a.png"
"$ICEF" info "$WORK/a" > "$WORK/info.txt"
grep -q "train 3, test 12" "$WORK/info.txt"
grep -q "observed 6 near 2 moderate 2 far 2" "$WORK/info.txt"

"$ICEF" synth --out "$WORK/b" --identity-seed 3 --k 3 --res 32 --test-views 2 --novel-per-tier 1 --threads 1 > /dev/null
diff -r "$WORK/a" "$WORK/b"  # deterministic: same seed, same bytes (any thread count)

# The face model fitted to the synthetic subject's landmarks, outlined by icef mask.
"$ICEF" mask "$WORK/a" --out "$WORK/mask" --threads 2 > "$WORK/mask.txt"
test -s "$WORK/mask/fit_frame0.png"
rms=$(sed -n 's/^face fit: landmark RMS \([0-9.e-]*\) IOD.*/\1/p' "$WORK/mask.txt")
test -n "$rms"
awk -v r="$rms" 'BEGIN { exit !(r < 0.02) }' || { echo "face fit RMS $rms IOD, expected < 0.02"; exit 1; }

"$ICEF" sheet "$WORK/a" --out "$WORK/sheet.png" --tile 32 > /dev/null
test -s "$WORK/sheet.png"

set +e
"$ICEF" synth --out "$WORK/c" --near 0.9 --far 0.5 2> "$WORK/err.txt"
code=$?
set -e
test "$code" -eq 1
grep -q "tier thresholds" "$WORK/err.txt"
echo "synth integration test passed"
