#!/usr/bin/env bash
# icef faceid on real photos installed by Debian packages (scripts/install-deps.sh installs them
# and the face-identity model): two webcam frames of one woman (opencv-doc), the astronaut
# (python3-skimage) and Grace Hopper (python-matplotlib-data). Checks the descriptors' size, that
# only the same-person pair is flagged under 0.6, the JSON output, and the error paths.
set -euo pipefail
ICEF="$1"
HTML=/usr/share/doc/opencv-doc/opencv4/html
PHOTOS=("$HTML/Cascade_Classifier_Tutorial_Result_Haar.jpg" "$HTML/Cascade_Classifier_Tutorial_Result_LBP.jpg"
        /usr/lib/python3/dist-packages/skimage/data/astronaut.png
        /usr/share/matplotlib/mpl-data/sample_data/grace_hopper.jpg)
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# A missing model is a clear error (exit 1), whatever is installed.
if "$ICEF" faceid --faceid-model "$TMP/none" "${PHOTOS[0]}" 2>"$TMP/err"; then fail "missing model accepted"; fi
grep -q "face-identity model not found" "$TMP/err" || fail "unclear missing-model error: $(cat "$TMP/err")"

MODEL="${ICEF_FACEID_MODEL:-/usr/local/share/icef/face-api}"
for f in "$MODEL/face_recognition_model.bin" /usr/share/dlib/shape_predictor_68_face_landmarks.dat "${PHOTOS[@]}"; do
  if [ ! -f "$f" ]; then echo "SKIP: $f not installed (run scripts/install-deps.sh)"; exit 77; fi
done

"$ICEF" faceid "${PHOTOS[@]}" >"$TMP/out.txt" || fail "faceid exited $?"
cat "$TMP/out.txt" | cut -c1-160
[ "$(grep -c '^  descriptor: \[' "$TMP/out.txt")" = 4 ] || fail "expected 4 descriptors"
while read -r line; do
  n=$(echo "$line" | tr -cd ',' | wc -c)
  [ "$n" = 127 ] || fail "descriptor with $((n + 1)) values"
done < <(grep '^  descriptor: \[' "$TMP/out.txt")
grep -Eq '^  0 - 1  distance 0\.[0-5][0-9]*  cosine [0-9.]+  same person$' "$TMP/out.txt" || fail "same-person pair not flagged"
[ "$(grep -c 'different people$' "$TMP/out.txt")" = 5 ] || fail "expected 5 different-people pairs"
[ "$(grep -c 'same person$' "$TMP/out.txt")" = 1 ] || fail "expected exactly 1 same-person pair"

"$ICEF" faceid --json "${PHOTOS[0]}" "${PHOTOS[1]}" >"$TMP/out.json" || fail "faceid --json exited $?"
grep -q '"same_person": true' "$TMP/out.json" || fail "JSON lacks same_person: true"
grep -q '"landmarks": "detector"' "$TMP/out.json" || fail "JSON lacks landmark source"
[ "$(grep -c '"descriptor": \[' "$TMP/out.json")" = 2 ] || fail "JSON lacks descriptors"

# A missing image is an error naming the file.
if "$ICEF" faceid "$TMP/missing.png" 2>"$TMP/err"; then fail "missing image accepted"; fi
grep -q "missing.png" "$TMP/err" || fail "error does not name the file: $(cat "$TMP/err")"
echo "faceid_test: OK"
