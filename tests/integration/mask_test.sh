#!/usr/bin/env bash
# Integration test of `icef mask`: writes a tiny dataset whose 68 landmarks form a schematic face
# (2D-only, then 3D), runs the command, and checks the files, the printed paths, the pixels where
# the mask must and must not be, and the error paths. Needs python3 (standard library only).
set -euo pipefail
ICEF="$1"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT

# make_dataset DIR MODE: MODE is 2d, 3d or none (which landmarks the frames carry).
make_dataset() {
python3 - "$1" "$2" <<'PY'
import json, math, os, struct, sys, zlib
root, mode = sys.argv[1], sys.argv[2]
os.makedirs(os.path.join(root, "images"), exist_ok=True)
W, H, F = 96, 80, 110.0

def face():
    p = [None] * 68
    for i in range(17):
        a = math.pi * i / 16
        p[i] = (-0.7 * math.cos(a), 0.2 - 0.75 * math.sin(a), -0.3 + 0.45 * math.sin(a))
    for i in range(5):
        x, y = 0.12 + 0.43 * (4 - i) / 4, 0.45 + 0.05 * math.sin(math.pi * i / 4)
        p[17 + i] = (-x, y, 0.2); p[26 - i] = (x, y, 0.2)
    for i in range(4): p[27 + i] = (0.0, 0.3 - 0.1 * i, 0.25 + 0.07 * i)
    for i in range(5): p[31 + i] = (-0.12 + 0.06 * i, -0.08, 0.3)
    for e in range(2):
        for i in range(6):
            a = math.pi - 2 * math.pi * i / 6
            p[36 + 6 * e + i] = ((-0.3 if e == 0 else 0.3) + 0.1 * math.cos(a), 0.3 + 0.04 * math.sin(a), 0.2)
    for i in range(12):
        a = math.pi - 2 * math.pi * i / 12
        p[48 + i] = (0.22 * math.cos(a), -0.28 + 0.09 * math.sin(a), 0.3)
    for i in range(8):
        a = math.pi - 2 * math.pi * i / 8
        p[60 + i] = (0.15 * math.cos(a), -0.28 + 0.04 * math.sin(a), 0.31)
    return p

def look_at(eye):  # camera-to-world, NeRF convention (camera looks down -Z)
    back = [e / math.sqrt(sum(c * c for c in eye)) for e in eye]
    up = (0.0, 1.0, 0.0)
    right = (up[1] * back[2] - up[2] * back[1], up[2] * back[0] - up[0] * back[2], up[0] * back[1] - up[1] * back[0])
    n = math.sqrt(sum(c * c for c in right)); right = [c / n for c in right]
    cup = (back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2], back[0] * right[1] - back[1] * right[0])
    return [[right[r], cup[r], back[r], eye[r]] for r in range(3)] + [[0, 0, 0, 1]]

def project(m, p):
    d = [p[i] - m[i][3] for i in range(3)]
    q = [sum(m[r][c] * d[r] for r in range(3)) for c in range(3)]  # R^T (p - C)
    return (W / 2 + F * q[0] / -q[2], H / 2 - F * q[1] / -q[2])

def png(path, pixels):  # pixels: rows of (r, g, b) bytes
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in pixels)
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))

lm3 = face()
def split(name, yaws):
    frames = []
    for k, yaw in enumerate(yaws):
        m = look_at((3 * math.sin(yaw), 0.3, 3 * math.cos(yaw)))
        uv = [project(m, p) for p in lm3]
        # A grey face-ish ellipse on white.
        pix = [[(170, 140, 120) if ((x + 0.5 - W / 2) / 30) ** 2 + ((y + 0.5 - H / 2) / 36) ** 2 < 1 else (255, 255, 255)
                for x in range(W)] for y in range(H)]
        png(os.path.join(root, "images", "%s_%03d.png" % (name, k)), pix)
        f = {"file_path": "images/%s_%03d.png" % (name, k), "transform_matrix": m,
             "expression": [0.1 * k, 0.0, -0.05 * k]}
        if mode == "2d": f["landmarks_2d"] = [list(u) for u in uv]
        if mode == "3d": f["landmarks_3d"] = [list(p) for p in lm3]
        frames.append(f)
    doc = {"w": W, "h": H, "fl_x": F, "fl_y": F, "cx": W / 2, "cy": H / 2, "aabb": [[-1, -1, -1], [1, 1, 1]],
           "expression_dim": 3, "background": [1, 1, 1], "frames": frames}
    with open(os.path.join(root, "transforms_%s.json" % name), "w") as f:
        json.dump(doc, f)
split("train", [-0.5, 0.0, 0.5])
split("test", [0.25])
# What the checks need: where the mouth centre and the nose tip project in training frame 1.
m = look_at((0.0, 0.3, 3.0))
with open(os.path.join(root, "expect.txt"), "w") as f:
    mouth, nose = project(m, (0.0, -0.28, 0.3)), project(m, lm3[30])
    f.write("%d %d %d %d\n" % (int(mouth[0]), int(mouth[1]), int(nose[0]), int(nose[1])))
PY
}

# pixel PNG X Y: prints "r g b" of an 8-bit RGB/grey PNG (any filter type).
pixel() {
python3 - "$1" "$2" "$3" <<'PY'
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
pos, idat = 8, b""
while pos < len(data):
    n, t = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    if t == b"IHDR": w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
    if t == b"IDAT": idat += body
    pos += 12 + n
ch = {0: 1, 2: 3, 4: 2, 6: 4}[ctype]
raw, stride, rows, prev = zlib.decompress(idat), w * ch, [], bytearray(w * ch)
for y in range(h):
    f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - ch] if i >= ch else 0
        b, c = prev[i], prev[i - ch] if i >= ch else 0
        if f == 1: line[i] = (line[i] + a) & 255
        elif f == 2: line[i] = (line[i] + b) & 255
        elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
        elif f == 4:
            p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
    rows.append(line); prev = line
x, y = int(sys.argv[2]), int(sys.argv[3])
px = rows[y][x * ch:(x + 1) * ch]
print(" ".join(str(v) for v in (list(px) * 3 if ch == 1 else list(px)[:3])))
PY
}

fail() { echo "mask_test: FAIL: $*" >&2; exit 1; }

for mode in 2d 3d; do
  DATA="$TMP/data_$mode"
  make_dataset "$DATA" "$mode"
  OUT="$TMP/out_$mode"
  "$ICEF" mask "$DATA" --out "$OUT" --frame 1 --threads 2 > "$TMP/stdout_$mode"
  cat "$TMP/stdout_$mode"
  if [ "$mode" = 2d ]; then grep -q "triangulated from landmarks_2d of 3 training views" "$TMP/stdout_$mode" || fail "2d source"; fi
  if [ "$mode" = 3d ]; then grep -q "landmarks_3d (mean over 3 training frames)" "$TMP/stdout_$mode" || fail "3d source"; fi
  for f in mask_overlay_frame1.png mask_projection_frame1.png mask_slice_xy.png mask_slice_xz.png mask_slice_yz.png; do
    [ -s "$OUT/$f" ] || fail "$f missing"
    grep -qF "$OUT/$f" "$TMP/stdout_$mode" || fail "$f path not printed"
  done
  read -r MX MY NX NY < "$DATA/expect.txt"
  # The projection is ~1 at the mouth centre, ~0 at the nose tip (the mouth capsule's soft edge,
  # margin 0.25 + softness 0.08 inter-ocular distances, ends just short of it) and 0 in the corner.
  read -r m _ _ <<< "$(pixel "$OUT/mask_projection_frame1.png" "$MX" "$MY")"
  read -r n _ _ <<< "$(pixel "$OUT/mask_projection_frame1.png" "$NX" "$NY")"
  read -r c _ _ <<< "$(pixel "$OUT/mask_projection_frame1.png" 2 2)"
  [ "$m" -ge 250 ] || fail "mask projection at the mouth is $m, expected ~255"
  [ "$n" -le 25 ] || fail "mask projection at the nose tip is $n, expected ~0"
  [ "$c" -eq 0 ] || fail "mask projection in the corner is $c, expected 0"
  # The overlay is red-tinted at the mouth (the skin there is (170, 140, 120)) and untouched in the corner.
  read -r r g b <<< "$(pixel "$OUT/mask_overlay_frame1.png" "$MX" "$MY")"
  [ "$r" -gt $((g + 80)) ] || fail "overlay at the mouth is ($r $g $b), expected red"
  [ "$(pixel "$OUT/mask_overlay_frame1.png" 2 2)" = "255 255 255" ] || fail "overlay corner changed"
done

# Errors: out-of-range frame, and a dataset without landmarks (exit code 1 with a message).
set +e
"$ICEF" mask "$TMP/data_2d" --out "$TMP/bad" --frame 7 2> "$TMP/err1"; rc1=$?
make_dataset "$TMP/data_none" none
"$ICEF" mask "$TMP/data_none" --out "$TMP/bad" 2> "$TMP/err2"; rc2=$?
set -e
[ "$rc1" -eq 1 ] && grep -q "out of range" "$TMP/err1" || fail "bad --frame: rc=$rc1 $(cat "$TMP/err1")"
[ "$rc2" -eq 1 ] && grep -q "landmarks" "$TMP/err2" || fail "no landmarks: rc=$rc2 $(cat "$TMP/err2")"
echo "mask_test: OK"
