#!/usr/bin/env bash
# `icef info` on a dataset this script writes (8x6 PNGs + transforms JSON): the summary on a good
# dataset; on malformed ones exit code 1, exactly one line on stderr naming file and field, and
# no file changed. Usage: info_test.sh PATH/TO/icef
set -euo pipefail
ICEF=$(realpath "$1")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

PNG_8x6='iVBORw0KGgoAAAANSUhEUgAAAAgAAAAGCAIAAABxZ0isAAAAoUlEQVR4nAGWAGn/ADWQ61q1EH/aNaT/Wskkf+5JpBNuyTiT7gBAm/ZlwBuK5UCvCmXUL4r5VK8eedRDnvkAS6YBcMsmlfBLuhVw3zqVBF+6KYTfTqkEAFaxDHvWMaD7VsUge+pFoA9qxTSP6lm0DwBhvBeG4TyrBmHQK4b1UKsaddA/mvVkvxoAbMcikexHthFs2zaRAFu2JYDbSqUAb8olISlGUZroXh8AAAAASUVORK5CYII='

# frame FILE TX EXPRESSION [EXTRA]: one frame object; camera at (TX, 0, 3) looking down -Z.
frame() {
  echo "{\"file_path\": \"$1\", \"transform_matrix\": [[1,0,0,$2],[0,1,0,0],[0,0,1,3],[0,0,0,1]], \"expression\": $3${4:+, $4}}"
}

make_dataset() {  # make_dataset DIR
  local dir=$1 image
  mkdir -p "$dir/images"
  for image in train_0 train_1 train_2 test_0 test_1; do
    echo "$PNG_8x6" | base64 -d > "$dir/images/$image.png"
  done
  local header='"w": 8, "h": 6, "fl_x": 10, "fl_y": 10, "cx": 4, "cy": 3, "aabb": [[-1,-1,-1],[1,1,1]],
    "expression_dim": 2, "expression_names": ["jaw_open", "smile"], "background": [1,1,1],
    "tier_thresholds": [0.5, 1.0], "some_other_tool": {"ignored": true}'
  cat > "$dir/transforms_train.json" <<JSON
{ $header, "frames": [
  $(frame images/train_0.png -0.2 "[0, 0]"),
  $(frame images/train_1.png 0.0 "[1, 0]"),
  $(frame images/train_2 0.2 "[0, 2]")
] }
JSON
  cat > "$dir/transforms_test.json" <<JSON
{ $header, "frames": [
  $(frame images/test_0.png 0.1 "[1, 0]" '"delta": 0, "tier": "observed"'),
  $(frame images/test_1.png -0.1 "[1, 1.5]" '"delta": 1.5, "tier": "far"')
] }
JSON
}

checksums() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 sha256sum); }

# --- a good dataset -------------------------------------------------------------------------
make_dataset "$WORK/good"
out=$("$ICEF" info "$WORK/good") || fail "info on a good dataset exited $?"
for needle in "train 3, test 2, val 0" "8x6" "dim 2: jaw_open, smile" "observed 1" "far 1" \
              "train expression distance (pairwise): min 1, max 2.23607" "test delta:    min 0, max 1.5"; do
  grep -qF -- "$needle" <<<"$out" || fail "info output lacks '$needle':"$'\n'"$out"
done
json=$("$ICEF" info --json "$WORK/good") || fail "info --json exited $?"
grep -q '"expression_dim": 2' <<<"$json" || fail "info --json lacks expression_dim: $json"
grep -q '"test_missing": false' <<<"$json" || fail "info --json lacks test_missing"

# Without a test split, info says so.
make_dataset "$WORK/notest" && rm "$WORK/notest/transforms_test.json"
"$ICEF" info "$WORK/notest" | grep -q "no test frames" || fail "info does not mention the missing test split"

# --- malformed datasets: exit 1, one line on stderr naming file + field, nothing changed --------
expect_error() {  # expect_error NAME EXPECTED-SUBSTRING EDIT-COMMAND...
  local name=$1 expected=$2
  shift 2
  local dir="$WORK/$name"
  make_dataset "$dir"
  (cd "$dir" && "$@")
  local before after rc=0
  before=$(checksums "$dir")
  "$ICEF" info "$dir" >"$WORK/$name.out" 2>"$WORK/$name.err" || rc=$?
  after=$(checksums "$dir")
  [ "$rc" -eq 1 ] || fail "$name: exit code $rc, expected 1"
  [ "$(wc -l <"$WORK/$name.err")" -eq 1 ] || fail "$name: stderr is not one line: $(cat "$WORK/$name.err")"
  [ ! -s "$WORK/$name.out" ] || fail "$name: printed on stdout: $(cat "$WORK/$name.out")"
  grep -qF -- "$expected" "$WORK/$name.err" || fail "$name: stderr '$(cat "$WORK/$name.err")' lacks '$expected'"
  [ "$before" = "$after" ] || fail "$name: dataset files changed"
  echo "ok: $name: $(cat "$WORK/$name.err")"
}

expect_error empty_train "transforms_train.json: frames: the train split has no frames" \
  python3 -c 'import json; d = json.load(open("transforms_train.json")); d["frames"] = []; json.dump(d, open("transforms_train.json", "w"))'
expect_error missing_image "transforms_train.json: frames[1].file_path: image not found" \
  rm images/train_1.png
expect_error non_rigid "transforms_train.json: frames[0].transform_matrix: rotation is not orthonormal" \
  sed -i 's/\[\[1,0,0,-0.2\]/[[2,0,0,-0.2]/' transforms_train.json
expect_error non_finite "transforms_test.json: frames[1].transform_matrix: non-finite value NaN" \
  sed -i 's/\[\[1,0,0,-0.1\]/[[1,0,0,NaN]/' transforms_test.json
expect_error expression_length "transforms_train.json: frames[2].expression: expected an array of 2 numbers, got 3 values" \
  sed -i 's/"expression": \[0, 2\]/"expression": [0, 2, 3]/' transforms_train.json
expect_error unknown_tier "transforms_test.json: frames[1].tier: unknown tier \"extreme\"" \
  sed -i 's/"tier": "far"/"tier": "extreme"/' transforms_test.json
expect_error wrong_type "transforms_train.json: fl_x: expected a number, got a string" \
  sed -i 's/"fl_x": 10/"fl_x": "10"/' transforms_train.json
expect_error size_mismatch "transforms_train.json: frames[0].file_path: image" \
  sed -i 's/"w": 8/"w": 16/' transforms_train.json
expect_error bad_json "transforms_test.json: invalid JSON" \
  sed -i 's/] }/]/' transforms_test.json
expect_error no_dataset "transforms_train.json: not found" \
  rm transforms_train.json

rc=0
"$ICEF" info "$WORK/does-not-exist" 2>/dev/null || rc=$?
[ "$rc" -eq 1 ] || fail "info on a missing directory exited $rc"
echo "info_test: all passed"
