#!/usr/bin/env bash
# `icef import` on a NerFace-style dataset this script writes (camera_angle_x, "intrinsics",
# per-frame 76-D expressions and bboxes, extension-less file paths, bg/00050.png), then
# `icef info` on the result; refusing a non-empty destination touches nothing.
# Usage: import_test.sh PATH/TO/icef
set -euo pipefail
ICEF=$(realpath "$1")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

PNG_8x8='iVBORw0KGgoAAAANSUhEUgAAAAgAAAAICAIAAABLbSncAAAA00lEQVR4nAHIADf/AGrFII/qRbQPatk0j/5ZtCN+2Uij/m3IIwB10Cua9VC/GnXkP5oJZL8uieRTrgl40y4AgNs2pQBbyiWA70qlFG/KOZTvXrkUg945AIvmQbALZtUwi/pVsB961USf+mnEH47pRACW8Uy7FnHgO5YFYLsqheBPqgV0zyqZ9E8AofxXxiF860ahEGvGNZDrWrUQf9o1pP9aAKwHYtEsh/ZRrBt20UCb9mXAG4rlQK8KZQC3Em3cN5IBXLcmgdxLpgFwyyaV8Eu6FXDfk1/BTKX6oQAAAABJRU5ErkJggg=='

expression() {  # expression SEED: 76 numbers
  local out="" i
  for ((i = 0; i < 76; i++)); do out+="${out:+, }0.$(( (i * 7 + $1 * 13) % 100 ))"; done
  echo "[$out]"
}

SRC="$WORK/person_1"
mkdir -p "$SRC/bg"
echo "$PNG_8x8" | base64 -d > "$SRC/bg/00050.png"
seed=0
for split in train val test; do
  mkdir -p "$SRC/$split"
  count=1; [ "$split" = train ] && count=3
  frames=""
  for ((i = 0; i < count; i++)); do
    name=$(printf "f_%04d" "$i")
    echo "$PNG_8x8" | base64 -d > "$SRC/$split/$name.png"
    seed=$((seed + 1))
    frames+="${frames:+,}
    {\"file_path\": \"./$split/$name\", \"bbox\": [0.1, 0.9, 0.2, 0.8],
     \"transform_matrix\": [[1,0,0,0.$i],[0,1,0,0],[0,0,1,1.5],[0,0,0,1]],
     \"expression\": $(expression $seed)}"
  done
  cat > "$SRC/transforms_$split.json" <<JSON
{"camera_angle_x": 0.5, "intrinsics": [17.5, 17.0, 0.5, 0.5], "frames": [$frames
]}
JSON
done

checksums() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 sha256sum); }
src_before=$(checksums "$SRC")

# NerFace loads directly...
"$ICEF" info "$SRC" | grep -q "dim 76" || fail "info on the NerFace dataset"
# ...and imports into our format.
out=$("$ICEF" import "$SRC" --out "$WORK/ours") || fail "import exited $?"
echo "$out"
grep -q "imported a nerface dataset" <<<"$out" || fail "import did not detect NerFace: $out"
[ "$(checksums "$SRC")" = "$src_before" ] || fail "import modified the source"
for f in transforms_train.json transforms_val.json transforms_test.json background.png images/train_0002.png images/val_0000.png; do
  [ -f "$WORK/ours/$f" ] || fail "import did not write $f"
done
grep -q '"expression_dim": 76' "$WORK/ours/transforms_train.json" || fail "no expression_dim in the imported JSON"
grep -q '"background_file_path": "background.png"' "$WORK/ours/transforms_train.json" || fail "no background_file_path"
grep -q '"fl_x": 17.5' "$WORK/ours/transforms_train.json" || fail "intrinsics not carried over"
info=$("$ICEF" info "$WORK/ours") || fail "info on the imported dataset exited $?"
grep -qF "train 3, test 1, val 1" <<<"$info" || fail "imported frame counts: $info"
grep -qF "cx 4.5, cy 4.5" <<<"$info" || fail "imported principal point: $info"

# A second import into the same place is refused and changes nothing.
ours_before=$(checksums "$WORK/ours")
rc=0
"$ICEF" import "$SRC" --out "$WORK/ours" 2>"$WORK/err" || rc=$?
[ "$rc" -eq 1 ] || fail "re-import exited $rc, expected 1"
[ "$(wc -l <"$WORK/err")" -eq 1 ] || fail "re-import stderr is not one line"
[ "$(checksums "$WORK/ours")" = "$ours_before" ] || fail "refused import changed the destination"

# A broken source: exit 1, no destination left behind.
rm "$SRC/train/f_0001.png"
rc=0
"$ICEF" import "$SRC" --out "$WORK/broken" 2>"$WORK/err" || rc=$?
[ "$rc" -eq 1 ] || fail "import of a broken source exited $rc"
grep -qF "transforms_train.json: frames[1].file_path: image not found" "$WORK/err" || fail "message: $(cat "$WORK/err")"
[ ! -e "$WORK/broken" ] || fail "a failed import left $WORK/broken"
ls -A "$WORK" | grep -q import- && fail "a failed import left a temporary directory"

rc=0
"$ICEF" import "$SRC" --out "$WORK/x" --format colmap 2>/dev/null || rc=$?
[ "$rc" -eq 1 ] || fail "an unknown --format exited $rc"
echo "import_test: all passed"
