#!/usr/bin/env bash
# icef synth end to end: a tiny dataset, read back by `icef info`, rendered twice to the same
# bytes, the expression style (style.json, --generic-style), the face model fitted to it (icef
# mask), a contact sheet from `icef sheet`, the drawn resolution's cap (--max-res), and a bad
# option rejected with exit code 1.
set -euo pipefail
ICEF="$1"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT

"$ICEF" synth --out "$WORK/a" --identity-seed 3 --k 3 --res 32 --test-views 2 --novel-per-tier 1 \
  --threads 2 --contact-sheet "$WORK/sheet_a.png" > "$WORK/log.txt"
grep -q "wrote $WORK/a: 3 train + 12 test frames" "$WORK/log.txt"
grep -q "expression style: the identity's own; style gap 0\.[0-9]" "$WORK/log.txt"
grep -q '"generic_style": false' "$WORK/a/style.json"
test -s "$WORK/sheet_a.png"
"$ICEF" info "$WORK/a" > "$WORK/info.txt"
grep -q "train 3, test 12" "$WORK/info.txt"
grep -q "observed 6 near 2 moderate 2 far 2" "$WORK/info.txt"

"$ICEF" synth --out "$WORK/b" --identity-seed 3 --k 3 --res 32 --test-views 2 --novel-per-tier 1 --threads 1 > /dev/null
diff -r "$WORK/a" "$WORK/b"  # deterministic: same seed, same bytes (any thread count)

# --generic-style: the face model's own expressions (gap 0); same shape, so neutral frames agree.
"$ICEF" synth --out "$WORK/g" --identity-seed 3 --k 3 --res 32 --test-views 2 --novel-per-tier 1 --threads 2 \
  --generic-style > "$WORK/log_g.txt"
grep -q "style gap 0.000" "$WORK/log_g.txt"
grep -q '"generic_style": true' "$WORK/g/style.json"
cmp "$WORK/a/images/test_neutral_000.png" "$WORK/g/images/test_neutral_000.png"
if cmp -s "$WORK/a/images/train_000.png" "$WORK/g/images/train_000.png"; then
  echo "the identity's style and the generic style rendered the same training frame" >&2
  exit 1
fi

# The face model fitted to the subjects' landmarks, outlined by icef mask: close on the generic
# style (the face model's own expressions), within the warning threshold on the identity's style.
fit_rms() {
  "$ICEF" mask "$1" --out "$2" --threads 2 > "$2.txt"
  test -s "$2/fit_frame0.png"
  sed -n 's/^face fit: landmark RMS \([0-9.e-]*\) IOD.*/\1/p' "$2.txt"
}
rms=$(fit_rms "$WORK/g" "$WORK/mask_g")
awk -v r="$rms" 'BEGIN { exit !(r < 0.02) }' || { echo "face fit RMS $rms IOD (generic style), expected < 0.02"; exit 1; }
rms=$(fit_rms "$WORK/a" "$WORK/mask_a")
awk -v r="$rms" 'BEGIN { exit !(r < 0.1) }' || { echo "face fit RMS $rms IOD (styled), expected < 0.1"; exit 1; }

"$ICEF" sheet "$WORK/a" --out "$WORK/sheet.png" --tile 32 > /dev/null
test -s "$WORK/sheet.png"

# --diverse --max-res: the drawn resolution stays within the cap (icef bench --validation draws up
# to 256); a cap of 128 leaves 128 alone; a cap below 128 is refused.
drawn_res() {
  "$ICEF" synth --out "$WORK/$1" --diverse --identity-seed 102 --max-res "$2" --k 3 --test-views 1 --novel-per-tier 1 \
    --supersample 1 --threads 2 > /dev/null
  sed -n 's/^ *"resolution": \([0-9]*\),*$/\1/p' "$WORK/$1/scene.json"
}
r=$(drawn_res d256 256)
case "$r" in 128|160|192|256) ;; *) echo "--max-res 256 drew resolution '$r'" >&2; exit 1 ;; esac
r=$(drawn_res d128 128)
test "$r" = 128 || { echo "--max-res 128 drew resolution '$r'" >&2; exit 1; }
if "$ICEF" synth --out "$WORK/d100" --diverse --max-res 100 2> /dev/null; then
  echo "--max-res 100 was accepted" >&2
  exit 1
fi

set +e
"$ICEF" synth --out "$WORK/c" --near 0.9 --far 0.5 2> "$WORK/err.txt"
code=$?
set -e
test "$code" -eq 1
grep -q "tier thresholds" "$WORK/err.txt"
echo "synth integration test passed"
