#!/usr/bin/env bash
# Driving an avatar from another person's video, end to end, on a clip the tests make themselves
# (synthetic photos of one subject, icef_make_clip): icef track CLIP --curves writes one row of ARKit
# weights and head rotation per frame (Live Link Face's layout), whose head yaw follows the clip's
# true yaw; an avatar of another subject (tracked with ICT-FaceKit, trained for a few steps) renders
# those curves as an MP4 that ffprobe reads with one frame per row and the duration rows / fps.
# Bad input: --curves on photos, or with --out, gets one line and writes nothing.
set -euo pipefail
ICEF="$1"
CLIP="$2"
for f in /usr/share/dlib/shape_predictor_68_face_landmarks.dat /usr/local/share/icef/facemesh/facemesh.bin; do
  if [ ! -f "$f" ]; then echo "SKIP: $f not installed (run scripts/install-deps.sh)"; exit 77; fi
done
command -v ffprobe >/dev/null || { echo "FAIL: no ffprobe (scripts/install-deps.sh installs ffmpeg)" >&2; exit 1; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# The driving clip: 8 frames of one subject at 4 fps.
"$ICEF" synth --photos 8 --out "$TMP/driver" --identity-seed 3 --res-photo 320x240 >/dev/null || fail "synth --photos"
"$CLIP" "$TMP/clip.mp4" 4 "$TMP"/driver/photos/photo_*.png || fail "make_clip"

"$ICEF" track "$TMP/clip.mp4" --curves "$TMP/drive.csv" --threads 2 >"$TMP/curves.log" 2>&1 \
  || { cat "$TMP/curves.log"; fail "icef track --curves"; }
cat "$TMP/curves.log"
grep -q "wrote $TMP/drive.csv: 8 rows at 4 fps, 51 ARKit curves" "$TMP/curves.log" || fail "no summary line"
/usr/bin/python3 - "$TMP/drive.csv" "$TMP/driver/truth/truth.json" "$TMP/curves.log" <<'PY' || fail "the curves"
import csv, json, sys
import numpy as np
rows = list(csv.reader(open(sys.argv[1])))
head, body = rows[0], rows[1:]
assert head[:2] == ["Timecode", "BlendShapeCount"], head[:2]
assert head[-3:] == ["HeadYaw", "HeadPitch", "HeadRoll"], head[-3:]
assert {"JawOpen", "EyeBlinkLeft", "MouthSmileRight", "BrowInnerUp"} <= set(head) and len(head) == 2 + 51 + 3, len(head)
assert len(body) == 8, len(body)
assert all(r[1] == "54" for r in body)
w = np.array([[float(c) for c in r[2:-3]] for r in body])
assert (w >= 0).all() and (w <= 1).all()
# Timecodes at 4 fps: frame k at second k // 4, frame k % 4.
assert [r[0] for r in body[:5]] == ["00:00:00:00.000", "00:00:00:01.000", "00:00:00:02.000",
                                   "00:00:00:03.000", "00:00:01:00.000"], [r[0] for r in body[:5]]
yaw = np.degrees([float(r[-3]) for r in body])
truth = json.load(open(sys.argv[2]))
true_yaw = np.array([p["head_pose_deg"]["yaw"] for p in truth["photos"]])
# Frames the log names as without a face repeat a neighbour's curves: not compared.
untracked = set()
for line in open(sys.argv[3]):
    if "without exactly one face" in line:
        untracked = {round(float(t), 2) for t in line.split(", at")[1].replace("s", "").split()}
tracked = [k for k in range(8) if round(k / 4, 2) not in untracked]
assert len(tracked) >= 6, untracked
err = np.abs(yaw - true_yaw)[tracked]
print(f"head yaw: tracked {np.round(yaw, 1)}, true {np.round(true_yaw, 1)}; max error {err.max():.1f} deg "
      f"over the {len(tracked)} frames with a face")
assert err.max() < 8, err
PY

# Bad input: photos, or a dataset asked for too; nothing written.
if "$ICEF" track "$TMP"/driver/photos/photo_000.png --curves "$TMP/bad.csv" 2>"$TMP/err" >/dev/null; then
  fail "--curves accepted a photo"
fi
[ "$(wc -l <"$TMP/err")" = 1 ] && grep -q "give one video" "$TMP/err" || fail "photo: $(cat "$TMP/err")"
if "$ICEF" track "$TMP/clip.mp4" --curves "$TMP/bad.csv" --out "$TMP/ds" 2>"$TMP/err" >/dev/null; then
  fail "--curves accepted --out"
fi
[ "$(wc -l <"$TMP/err")" = 1 ] && grep -q "leave out --out" "$TMP/err" || fail "--out: $(cat "$TMP/err")"
[ ! -e "$TMP/bad.csv" ] && [ ! -e "$TMP/ds" ] || fail "something was written"

# The avatar: another subject, tracked with ICT-FaceKit, a tiny model trained for a few steps.
"$ICEF" synth --photos 4 --out "$TMP/subject" --identity-seed 5 --res-photo 320x240 >/dev/null || fail "synth"
"$ICEF" track "$TMP/subject/photos" --face-model ict --res 48 --threads 2 --out "$TMP/ds" >"$TMP/track.log" 2>&1 \
  || { cat "$TMP/track.log"; fail "icef track --face-model ict"; }
TINY=(--set model.static_field.grid.num_levels=4 --set model.static_field.grid.log2_table_size=10
      --set model.static_field.grid.finest_resolution=32 --set model.static_field.density_hidden=16
      --set "model.static_field.color_hidden=[16]" --set "model.deformation.hidden=[16,16]"
      --set model.sampler.num_samples=16 --set model.occupancy.resolution=16 --set train.batch_rays=256)
"$ICEF" train "$TMP/ds" --out "$TMP/model" --method icef-prior --steps 10 --threads 2 --quiet "${TINY[@]}" >/dev/null \
  || fail "icef train"
"$ICEF" render "$TMP/model" --expressions "$TMP/drive.csv" --video "$TMP/drive.mp4" --fps 4 --res 32 --threads 2 \
  --out "$TMP/render" >"$TMP/render.log" 2>&1 || { cat "$TMP/render.log"; fail "icef render --expressions"; }
grep -q "^--expressions: 8 frames from .*drive.csv; columns with no blendshape of the model, ignored: HeadYaw HeadPitch HeadRoll$" \
  "$TMP/render.log" || fail "render does not name the CSV's unused columns: $(head -3 "$TMP/render.log")"
probe=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames,codec_name \
  -show_entries format=duration -of default=noprint_wrappers=1 "$TMP/drive.mp4") || fail "ffprobe cannot read the MP4"
echo "$probe"
grep -q "codec_name=h264" <<<"$probe" || fail "not H.264"
grep -q "nb_read_frames=8" <<<"$probe" || fail "not one frame per row"
duration=$(sed -n 's/^duration=//p' <<<"$probe")
/usr/bin/python3 -c "import sys; d = float(sys.argv[1]); assert abs(d - 2.0) < 0.3, d" "$duration" \
  || fail "duration $duration s, expected 8 rows / 4 fps = 2 s"
echo "PASS"
