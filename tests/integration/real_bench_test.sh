#!/usr/bin/env bash
# Video in and the real-media protocol end to end, on a clip the tests make themselves: synthetic
# photos of one subject (icef synth --photos) encoded as an MP4 by the tests' own encoder
# (icef_make_clip, video/video_writer.h); icef track decodes it, tracks the sampled frames and
# chooses the training frames for coverage; icef bench --real (--quick) tracks, trains and scores
# the held-out frames of the clip and of a photo folder, writes the report, and resumes; a truncated
# and a non-video .mp4 get one clear line and exit 1, and nothing is written.
set -euo pipefail
ICEF="$1"
CLIP="$2"
for f in /usr/share/dlib/shape_predictor_68_face_landmarks.dat /usr/local/share/icef/facemesh/facemesh.bin; do
  if [ ! -f "$f" ]; then echo "SKIP: $f not installed (run scripts/install-deps.sh)"; exit 77; fi
done
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$ICEF" synth --photos 8 --out "$TMP/ph" --identity-seed 3 --res-photo 320x240 >/dev/null || fail "synth --photos"
"$CLIP" "$TMP/clip.mp4" 4 "$TMP"/ph/photos/photo_*.png || fail "make_clip"

# Video in: 8 frames decoded, 3 chosen for training, 2 held out, the rest left out.
"$ICEF" track "$TMP/clip.mp4" --frames 3 --test 2 --res 64 --threads 2 --out "$TMP/track" >"$TMP/track.log" 2>&1 \
  || { cat "$TMP/track.log"; fail "icef track on a video"; }
grep -q "clip.mp4, 320x240" "$TMP/track.log" || fail "no video summary: $(head -3 "$TMP/track.log")"
grep -q "training frames chosen for coverage" "$TMP/track.log" || fail "the coverage choice is not reported"
/usr/bin/python3 - "$TMP/track" <<'PY' || fail "tracked video dataset"
import json, sys
d = sys.argv[1]
train = json.load(open(f"{d}/transforms_train.json"))["frames"]
test = json.load(open(f"{d}/transforms_test.json"))["frames"]
assert len(train) == 3 and len(test) == 2, (len(train), len(test))
rep = json.load(open(f"{d}/track/report.json"))["photos"]
times = {p["split"]: [] for p in rep}
for p in rep:
    assert p["time_s"] is not None and p["name"].startswith("clip.mp4@"), p
    times[p["split"]].append(p["time_s"])
assert times["test"] == sorted(times["test"]), times  # held out in time order
assert len(set(times["train"]) | set(times["test"])) == 5
PY
"$ICEF" info "$TMP/track" >/dev/null || fail "the tracked video dataset does not validate"

# Bad videos: one line naming the file, exit 1, nothing written.
head -c 3000 "$TMP/clip.mp4" >"$TMP/truncated.mp4"
echo "not a video" >"$TMP/text.mp4"
for bad in truncated text; do
  if "$ICEF" track "$TMP/$bad.mp4" --frames 3 --out "$TMP/bad_$bad" 2>"$TMP/err" >/dev/null; then fail "accepted $bad.mp4"; fi
  [ "$(wc -l <"$TMP/err")" = 1 ] || fail "$bad.mp4: more than one line: $(cat "$TMP/err")"
  grep -q "$bad.mp4" "$TMP/err" || fail "$bad.mp4: the error does not name the file: $(cat "$TMP/err")"
  [ ! -e "$TMP/bad_$bad" ] || fail "$bad.mp4: something was written"
done

# The real protocol on the clip and on a photo folder (the same subject's photos).
"$ICEF" bench --real "$TMP/clip.mp4" "$TMP/ph/photos" --quick --threads 2 --out "$TMP/real" >"$TMP/real.log" 2>&1 \
  || { tail -20 "$TMP/real.log"; fail "bench --real"; }
for f in report.md report.json report.tex runs/clip_k3_icef-prior/metrics.json runs/photos_k3_icef/metrics.json; do
  [ -s "$TMP/real/$f" ] || fail "bench --real wrote no $f"
done
ls "$TMP"/real/worst_clip_k3_*.png >/dev/null || fail "no worst-frame sheet"
/usr/bin/python3 - "$TMP/real/report.json" <<'PY' || fail "real report"
import json, math, sys
r = json.load(open(sys.argv[1]))
runs = {(x["source"], x["k"], x["method"]): x for x in r["runs"]}
assert set(runs) == {("clip", 3, "icef-prior"), ("clip", 3, "icef"), ("photos", 3, "icef-prior"), ("photos", 3, "icef")}, runs.keys()
for key, run in runs.items():
    m = run["metrics"]["means"]
    assert m["count"] == 2, (key, m)
    for k in ("face_psnr", "face_psnr_nearest", "head_psnr", "face_ssim", "track_rms_iod"):
        assert m[k] is not None and math.isfinite(m[k]), (key, k, m)
    assert 0 < m["face_psnr"] < 60, m  # 20 steps of a tiny model: a fog, but measured
    assert 0 <= m["track_rms_iod"] < 0.15, m
    for f in run["metrics"]["frames"]:
        g = f["real_expr_gain"]
        assert g is None or g <= 1.0, f
sources = {s["name"]: s for s in r["sources"]}
assert sources["clip"]["held_out_frames"] == 2 and sources["photos"]["held_out_frames"] == 2, sources
PY
grep -q "real_expr_gain" "$TMP/real/report.md" || fail "report.md has no real_expr_gain"
grep -q 'tab:icef-bench-real' "$TMP/real/report.tex" || fail "report.tex has no table"
# Resume: every run is done, nothing is trained again.
"$ICEF" bench --real "$TMP/clip.mp4" "$TMP/ph/photos" --quick --threads 2 --out "$TMP/real" >"$TMP/real2.log" 2>&1 \
  || fail "bench --real resume"
if grep -q "train clip" "$TMP/real2.log"; then fail "a finished run was trained again"; fi
echo "real_bench_test: ok"
