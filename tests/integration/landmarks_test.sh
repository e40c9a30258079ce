#!/usr/bin/env bash
# Integration test of `icef landmarks`: a synthetic head dataset (icef synth, K = 3, 160x160) has
# its landmarks removed, the command detects them with dlib, and the result is checked: 68 points
# and 68 visibility flags on every frame, the mean distance to the generator's ground-truth
# landmarks, other keys kept, reruns (kept frames, --overwrite, thread-count determinism), and
# the no-face cases: a blank test frame is a warning (exit 0), a blank training frame an error
# (exit 1) naming the frame, with the other frames' landmarks saved. Needs python3 (stdlib only).
set -euo pipefail
ICEF="$1"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

if [ ! -f /usr/share/dlib/shape_predictor_68_face_landmarks.dat ]; then
  echo "SKIP: dlib's shape predictor not installed (Debian libdlib-data; run scripts/install-deps.sh)"
  exit 77
fi

D="$TMP/head"
"$ICEF" synth --out "$D" --k 3 --res 160 --test-views 1 >/dev/null || fail "synth exited $?"

# Keep the ground truth aside; strip every landmark and add a key of another tool.
python3 - "$D" <<'PY'
import json, shutil, sys
root = sys.argv[1]
for split in ("train", "test"):
    path = f"{root}/transforms_{split}.json"
    shutil.copy(path, f"{root}/../truth_{split}.json")
    doc = json.load(open(path))
    for f in doc["frames"]:
        for key in ("landmarks_2d", "landmarks_2d_visible", "landmarks_3d"):
            f.pop(key, None)
        f["other_tool"] = {"keep": split}
    json.dump(doc, open(path, "w"), indent=1)
PY

"$ICEF" landmarks "$D" --threads 2 >"$TMP/out.txt" 2>"$TMP/err.txt" || fail "landmarks exited $?: $(cat "$TMP/err.txt")"
cat "$TMP/out.txt"
grep -q "^train: 3 frames, 3 detected, 0 without a face, 0 kept" "$TMP/out.txt" || fail "train summary"
grep -q "^test: 9 frames, 9 detected, 0 without a face, 0 kept" "$TMP/out.txt" || fail "test summary"
grep -q "a face was found in every processed frame" "$TMP/out.txt" || fail "missing all-found line"

# 68 points + 68 true flags per frame; mean error against the ground truth's visible landmarks.
python3 - "$D" <<'PY'
import json, math, sys
root = sys.argv[1]
errors, inner_errors, jaw_errors = [], [], []
for split in ("train", "test"):
    doc = json.load(open(f"{root}/transforms_{split}.json"))
    truth = json.load(open(f"{root}/../truth_{split}.json"))
    for i, (f, t) in enumerate(zip(doc["frames"], truth["frames"])):
        assert f["other_tool"] == {"keep": split}, f"{split}[{i}]: other key lost"
        assert "landmarks_3d" not in f
        lm, vis = f["landmarks_2d"], f["landmarks_2d_visible"]
        assert len(lm) == 68 and all(len(p) == 2 for p in lm), f"{split}[{i}]: not 68 points"
        assert vis == [True] * 68, f"{split}[{i}]: visibility not all true"
        d = {k: math.dist(lm[k], t["landmarks_2d"][k]) for k in range(68) if t["landmarks_2d_visible"][k]}
        mean = lambda ks: sum(d[k] for k in ks if k in d) / max(1, sum(1 for k in ks if k in d))
        errors.append(mean(range(68)))
        inner_errors.append(mean(range(17, 68)))  # brows, nose, eyes, mouth
        jaw_errors.append(mean(range(17)))
        print(f"  {split}[{i}] {f['file_path']}: mean error {errors[-1]:.2f} px over {len(d)} visible landmarks "
              f"(inner 17-67: {inner_errors[-1]:.2f} px, jaw 0-16: {jaw_errors[-1]:.2f} px)")
avg = lambda v: sum(v) / len(v)
print(f"mean landmark error vs ground truth (160x160): all {avg(errors):.2f} px, inner 17-67 {avg(inner_errors):.2f} px "
      f"(max per frame {max(inner_errors):.2f}), jaw 0-16 {avg(jaw_errors):.2f} px")
# The generator's landmarks are its own model of the iBUG points. Brows, eyes, nose and mouth
# (what the expression mask uses) agree with dlib to a few pixels; dlib's jaw line sits higher
# than the generator's chin points, so the jaw only gets a loose bound.
assert avg(inner_errors) < 5.0, f"inner mean error {avg(inner_errors):.2f} px"
assert max(inner_errors) < 7.0, f"inner max per-frame error {max(inner_errors):.2f} px"
assert avg(errors) < 9.0, f"mean error {avg(errors):.2f} px"
PY
"$ICEF" info "$D" >/dev/null || fail "dataset does not load after landmarks"

# A rerun keeps every frame (nothing to detect) and leaves the files byte-identical.
cp "$D/transforms_train.json" "$TMP/train_2threads.json"
cp "$D/transforms_test.json" "$TMP/test_2threads.json"
"$ICEF" landmarks "$D" >"$TMP/out.txt" || fail "rerun exited $?"
grep -q "^train: 3 frames, 0 detected, 0 without a face, 3 kept" "$TMP/out.txt" || fail "rerun did not keep frames"
cmp -s "$D/transforms_train.json" "$TMP/train_2threads.json" || fail "rerun changed the train file"
# --overwrite on one thread gives the same bytes as two threads (deterministic).
"$ICEF" landmarks "$D" --overwrite --threads 1 >"$TMP/out.txt" || fail "--overwrite exited $?"
grep -q "^train: 3 frames, 3 detected" "$TMP/out.txt" || fail "--overwrite did not re-detect"
cmp -s "$D/transforms_train.json" "$TMP/train_2threads.json" || fail "train landmarks differ between thread counts"
cmp -s "$D/transforms_test.json" "$TMP/test_2threads.json" || fail "test landmarks differ between thread counts"
# --splits limits the work.
"$ICEF" landmarks "$D" --overwrite --splits train >"$TMP/out.txt" || fail "--splits train exited $?"
if grep -q "^test:" "$TMP/out.txt"; then fail "--splits train processed test"; fi

# blank_png PATH: a white 160x160 RGB PNG (no face).
blank_png() {
python3 - "$1" <<'PY'
import struct, sys, zlib
w = h = 160
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
raw = b"".join(b"\x00" + b"\xff" * (3 * w) for _ in range(h))
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) + \
      chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
open(sys.argv[1], "wb").write(png)
PY
}
strip_landmarks() {
python3 - "$1" <<'PY'
import json, sys
for split in ("train", "test"):
    path = f"{sys.argv[1]}/transforms_{split}.json"
    doc = json.load(open(path))
    for f in doc["frames"]:
        f.pop("landmarks_2d", None); f.pop("landmarks_2d_visible", None)
    json.dump(doc, open(path, "w"), indent=1)
PY
}

# A blank test frame: reported, exit 0.
strip_landmarks "$D"
blank_png "$D/images/test_002.png"
"$ICEF" landmarks "$D" >"$TMP/out.txt" 2>"$TMP/err.txt" || fail "blank test frame: exited $? ($(cat "$TMP/err.txt"))"
grep -q "^test: 9 frames, 8 detected, 1 without a face" "$TMP/out.txt" || fail "blank test frame not counted"
grep -q "^no face found in 1 frame:" "$TMP/out.txt" || fail "no-face list missing"
grep -q "^  test\[2\] images/test_002.png" "$TMP/out.txt" || fail "blank test frame not named"

# A blank training frame: exit 1 naming it; the landmarks found are saved, the file stays valid.
strip_landmarks "$D"
blank_png "$D/images/train_001.png"
set +e
"$ICEF" landmarks "$D" >"$TMP/out.txt" 2>"$TMP/err.txt"
rc=$?
set -e
cat "$TMP/err.txt"
[ "$rc" = 1 ] || fail "blank training frame: expected exit 1, got $rc"
grep -q "no face found in 1 training frame: train\[1\] images/train_001.png" "$TMP/err.txt" || fail "error does not name the frame"
python3 - "$D" <<'PY'
import json, sys
doc = json.load(open(f"{sys.argv[1]}/transforms_train.json"))
have = ["landmarks_2d" in f for f in doc["frames"]]
assert have == [True, False, True], have
PY
"$ICEF" info "$D" >/dev/null || fail "dataset does not load after a partial run"
# The rerun processes only the frame still missing (and fails again on it).
if "$ICEF" landmarks "$D" --splits train >"$TMP/out.txt" 2>/dev/null; then fail "blank training frame accepted"; fi
grep -q "^train: 3 frames, 0 detected, 1 without a face, 2 kept" "$TMP/out.txt" || fail "rerun reprocessed frames"

# Errors: a bad split name, a missing predictor, a missing dataset.
if "$ICEF" landmarks "$D" --splits train,tset 2>"$TMP/err.txt"; then fail "bad split accepted"; fi
grep -q 'unknown split "tset"' "$TMP/err.txt" || fail "unclear split error: $(cat "$TMP/err.txt")"
if "$ICEF" landmarks "$D" --overwrite --predictor "$TMP/none.dat" 2>"$TMP/err.txt"; then fail "missing predictor accepted"; fi
grep -q "none.dat: 68-point shape predictor not found" "$TMP/err.txt" || fail "unclear predictor error: $(cat "$TMP/err.txt")"
if "$ICEF" landmarks "$TMP/nothing" 2>"$TMP/err.txt"; then fail "missing dataset accepted"; fi
grep -q "nothing" "$TMP/err.txt" || fail "error does not name the dataset"
echo "landmarks_test: OK"
