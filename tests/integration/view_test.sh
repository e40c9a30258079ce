#!/usr/bin/env bash
# icef view end to end in headless Chromium (Debian's chromium, driven by puppeteer-core through
# tests/integration/view_browser.js): a tiny synthetic avatar exported into a viewer folder and
# served by icef view --serve; the page loads with no console error, failed request or exception;
# a screenshot at the dataset camera with jaw_open at 1 differs from the neutral one in the mouth
# (more than elsewhere); the browser's neutral image at that camera covers the same pixels as
# icef render's (silhouette IoU) and agrees in colour within the head; ARKit curves given with
# --curves play (the frame advances, the weights change); a GLB given instead of a model works; bad
# input gets one line and leaves nothing behind.
set -euo pipefail
ICEF="$1"
WORK="$(mktemp -d)"
SERVER=""
trap '[ -n "$SERVER" ] && kill "$SERVER" 2>/dev/null; rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
for f in /usr/bin/chromium /usr/local/share/icef/puppeteer/node_modules/puppeteer-core/package.json \
         /usr/local/share/icef/three/build/three.module.js; do
  [ -e "$f" ] || fail "$f missing (scripts/install-deps.sh installs it)"
done

"$ICEF" synth --out "$WORK/data" --identity-seed 2 --k 3 --res 32 --test-views 1 --novel-per-tier 1 \
  --supersample 1 --threads 2 >/dev/null
TINY=(--set model.static_field.grid.num_levels=4 --set model.static_field.grid.log2_table_size=10
      --set model.static_field.grid.finest_resolution=32 --set model.static_field.density_hidden=16
      --set "model.static_field.color_hidden=[16]" --set "model.deformation.hidden=[16,16]"
      --set model.sampler.num_samples=16 --set model.occupancy.resolution=16 --set train.batch_rays=256)
"$ICEF" train "$WORK/data" --out "$WORK/model" --method icef-prior --steps 1000 --threads 2 --quiet "${TINY[@]}" \
  >/dev/null || fail "icef train"

# Curves in Live Link Face's layout: the page maps JawOpen onto the model's jaw_open.
{ echo "Timecode,BlendShapeCount,JawOpen,EyeBlinkLeft,HeadYaw"
  for i in $(seq 0 29); do echo "00:00:00:$(printf %02d "$i").000,3,0.$((i % 10)),0.5,0.1"; done; } >"$WORK/curves.csv"

"$ICEF" view "$WORK/model" --out "$WORK/view" --curves "$WORK/curves.csv" --resolution 48 --triangles 6000 \
  --threads 2 >"$WORK/view.log" 2>&1 || { cat "$WORK/view.log"; fail "icef view"; }
for f in index.html avatar.glb viewer.json curves.csv three/three.module.js three/addons/loaders/GLTFLoader.js; do
  [ -s "$WORK/view/$f" ] || fail "no $f in the viewer folder"
done
"$ICEF" view "$WORK/view" --serve --port 0 >"$WORK/serve.log" 2>&1 &
SERVER=$!
for _ in $(seq 50); do grep -q "http://127.0.0.1:" "$WORK/serve.log" && break; sleep 0.2; done
URL=$(sed -n 's/.* at \(http:[^ ]*\) .*/\1/p' "$WORK/serve.log")
[ -n "$URL" ] || fail "icef view --serve printed no URL: $(cat "$WORK/serve.log")"

node "$HERE/view_browser.js" "$URL" "$WORK/shots" --expr jaw_open:1 --bench 30 >"$WORK/browser.json" \
  || { cat "$WORK/browser.json"; fail "the viewer in headless Chromium"; }
"$ICEF" render "$WORK/model" --dataset "$WORK/data" --frame train:0 --out "$WORK/render" --threads 2 >/dev/null \
  || fail "icef render"
/usr/bin/python3 - "$WORK" <<'PY' || fail "the browser's images"
import json, sys
import numpy as np
from PIL import Image
work = sys.argv[1]
b = json.load(open(f"{work}/browser.json"))
assert b["errors"] == [] and b["ready"], b["errors"]
assert len(b["targets"]) == 11 and "jaw_open" in b["targets"], b["targets"]
assert b["camera"] == "train:0" and b["expr_changed"] and b["frames_advanced"], b
assert b["csv"]["columnsUsed"] and "HeadYaw" in b["csv"]["columnsUnused"], b["csv"]
load = lambda p: np.asarray(Image.open(p).convert("RGB"), dtype=float) / 255
neutral, jaw, render = load(f"{work}/shots/neutral.png"), load(f"{work}/shots/expr.png"), load(f"{work}/render/color_000.png")
assert neutral.shape == render.shape == (32, 32, 3), (neutral.shape, render.shape)
# The mouth: the box of the frame's landmarks 48-67, two pixels wider.
frame = json.load(open(f"{work}/data/transforms_train.json"))["frames"][0]
mouth = np.array(frame["landmarks_2d"])[48:68]
x0, y0 = np.floor(mouth.min(0)).astype(int) - 2
x1, y1 = np.ceil(mouth.max(0)).astype(int) + 2
inside = np.zeros((32, 32), bool)
inside[max(y0, 0):y1, max(x0, 0):x1] = True
diff = np.abs(jaw - neutral).sum(-1)
print(f"jaw_open: mean change {diff[inside].mean():.3f} in the mouth box, {diff[~inside].mean():.3f} elsewhere")
assert diff[inside].mean() > 2 * diff[~inside].mean() and diff[inside].mean() > 0.02
# Browser against icef render at the same camera and (neutral) expression; the head is where a pixel is
# clearly darker than the white background (the render's edge fades into it over a pixel or two).
a, r = neutral.min(-1) < 0.8, render.min(-1) < 0.8
iou = (a & r).sum() / (a | r).sum()
head = a | r
psnr = -10 * np.log10(((neutral - render) ** 2)[head].mean())
print(f"browser vs icef render at train:0: silhouette IoU {iou:.3f}, head PSNR {psnr:.1f} dB; fps {b['fps']:.1f}")
assert iou > 0.85 and psnr > 16, (iou, psnr)
PY

# A GLB instead of a model: no cameras, the same page.
"$ICEF" view "$WORK/view/avatar.glb" --out "$WORK/view_glb" >/dev/null || fail "icef view GLB"
grep -q '"cameras": \[\]' "$WORK/view_glb/viewer.json" || fail "a GLB's viewer has cameras"

# Bad input: one line naming the file, exit 1, nothing written or touched.
check_bad() {  # expected-text args...
  local want="$1"; shift
  if "$ICEF" view "$@" >/dev/null 2>"$WORK/err"; then fail "accepted: $*"; fi
  [ "$(wc -l <"$WORK/err")" = 1 ] || fail "more than one line for $*: $(cat "$WORK/err")"
  grep -q -- "$want" "$WORK/err" || fail "'$want' not in: $(cat "$WORK/err")"
}
echo "not a glb" >"$WORK/bad.glb"
check_bad "bad.glb" "$WORK/bad.glb" --out "$WORK/bad_view"
printf 'Timecode,JawOpen\n0,x\n' >"$WORK/bad.csv"
check_bad "bad.csv:2" "$WORK/model" --out "$WORK/bad_view" --curves "$WORK/bad.csv" --resolution 24
check_bad "missing" "$WORK/missing" --out "$WORK/bad_view"
[ ! -e "$WORK/bad_view" ] || fail "a failed icef view left $WORK/bad_view"
ls "$WORK" | grep -q "bad_view" && fail "a temporary folder was left: $(ls "$WORK")"
before=$(ls -l "$WORK/view" | md5sum)
check_bad "not an empty directory" "$WORK/model" --out "$WORK/view" --resolution 24
[ "$(ls -l "$WORK/view" | md5sum)" = "$before" ] || fail "a failed icef view touched an existing folder"
echo "PASS"
