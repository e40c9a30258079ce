#!/usr/bin/python3
"""How closely the browser shows an avatar: icef view's page in headless Chromium against icef render.

    scripts/view_agreement.py ICEF MODEL DATASET FRAME OUT_DIR [--view-args "..."] [--threads N]

Exports MODEL into a viewer folder (icef view), serves it, and screenshots the page
(tests/integration/view_browser.js) at the dataset camera of FRAME (a training frame, train:K) with
FRAME's expression; renders the same camera and expression with icef render; and writes OUT_DIR/
agreement.json (PSNR and SSIM-free error inside the face: the convex hull of the frame's 68
landmarks; PSNR over the head: where either image is clearly darker than the background; the
browser's frame rate) and OUT_DIR/agreement.png (browser | icef render | |difference| x 4, face hull
outlined), and OUT_DIR/viewer.png, the page as a user sees it. Both images are the dataset camera's size.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time

import numpy as np
from PIL import Image, ImageDraw

HERE = os.path.dirname(os.path.abspath(__file__))
DRIVER = os.path.join(HERE, "..", "tests", "integration", "view_browser.js")


def convex_hull(points):
    pts = sorted(map(tuple, points))
    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and (out[-1][0] - out[-2][0]) * (p[1] - out[-2][1]) - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0]) <= 0:
                out.pop()
            out.append(p)
        return out
    lower, upper = half(pts), half(reversed(pts))
    return lower[:-1] + upper[:-1]


def hull_mask(points, w, h):
    img = Image.new("L", (w, h), 0)
    ImageDraw.Draw(img).polygon([tuple(p) for p in convex_hull(points)], fill=1)
    return np.asarray(img, bool)


def psnr(a, b, mask):
    return float(-10 * np.log10(((a - b) ** 2)[mask].mean()))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("icef")
    ap.add_argument("model")
    ap.add_argument("dataset")
    ap.add_argument("frame", help="train:K")
    ap.add_argument("out")
    ap.add_argument("--view-args", default="", help="extra icef view options (e.g. --triangles 40000)")
    ap.add_argument("--threads", default="2")
    ap.add_argument("--neutral", action="store_true", help="the neutral expression instead of FRAME's")
    a = ap.parse_args()
    split, index = a.frame.split(":")
    if split != "train":
        sys.exit("view_agreement.py: FRAME must be a training frame (the viewer has the training cameras)")
    os.makedirs(a.out, exist_ok=True)
    transforms = json.load(open(os.path.join(a.dataset, "transforms_train.json")))
    names = transforms["expression_names"]
    frame = transforms["frames"][int(index)]
    # ICT-FaceKit's names as the GLB's ARKit ones: _L/_R -> Left/Right, the split pairs' halves averaged.
    weights = {}
    for n, v in zip(names, frame["expression"]):
        base = n[:-2] if n[-2:] in ("_L", "_R") else n
        if base in ("browInnerUp", "cheekPuff"):
            weights[base] = weights.get(base, 0) + v / 2
        else:
            weights[base + {"_L": "Left", "_R": "Right"}.get(n[-2:], "") if base != n else n] = v
    expr = ",".join(f"{n}:{v:.4f}" for n, v in weights.items() if v != 0 and not a.neutral)
    expr = expr or f"{names[0]}:0"
    with tempfile.TemporaryDirectory() as tmp:
        view = os.path.join(tmp, "view")
        t0 = time.time()
        subprocess.run([a.icef, "view", a.model, "--out", view, "--threads", a.threads, *shlex.split(a.view_args)],
                       check=True, stdout=subprocess.DEVNULL)
        export_s = time.time() - t0
        server = subprocess.Popen([a.icef, "view", view, "--serve", "--port", "0"], stdout=subprocess.PIPE, text=True)
        try:
            line = server.stdout.readline()
            url = line.split(" at ")[1].split()[0]
            shots = os.path.join(tmp, "shots")
            run = subprocess.run(["node", DRIVER, url, shots, "--camera", a.frame, "--expr", expr, "--bench", "60"],
                                 capture_output=True, text=True)
            browser = json.loads(run.stdout)
            if run.returncode != 0:
                sys.exit(f"view_agreement.py: the viewer failed: {browser['errors']}")
        finally:
            server.terminate()
        render_dir = os.path.join(tmp, "render")
        expression = [] if a.neutral else ["--expression-frame", a.frame]
        subprocess.run([a.icef, "render", a.model, "--dataset", a.dataset, "--frame", a.frame, *expression,
                        "--out", render_dir, "--threads", a.threads], check=True, stdout=subprocess.DEVNULL)
        Image.open(os.path.join(shots, "ui.png")).convert("RGB").save(os.path.join(a.out, "viewer.png"), optimize=True)
        load = lambda p: np.asarray(Image.open(p).convert("RGB"), dtype=float) / 255
        web, ref = load(os.path.join(shots, "expr.png")), load(os.path.join(render_dir, "color_000.png"))
    h, w = ref.shape[:2]
    face = hull_mask(np.array(frame["landmarks_2d"]), w, h)
    head = (web.min(-1) < 0.8) | (ref.min(-1) < 0.8)
    result = {
        "model": a.model, "dataset": a.dataset, "frame": a.frame, "expression": expr,
        "size": [w, h], "face_pixels": int(face.sum()),
        "face_psnr_db": round(psnr(web, ref, face), 2), "head_psnr_db": round(psnr(web, ref, head), 2),
        "face_mean_abs_error": round(float(np.abs(web - ref)[face].mean()), 4),
        "browser_fps_512": round(browser["fps"], 1), "export_and_view_s": round(export_s, 1),
    }
    diff = np.clip(np.abs(web - ref) * 4, 0, 1)
    sheet = Image.new("RGB", (3 * w, h))
    for i, img in enumerate([web, ref, diff]):
        sheet.paste(Image.fromarray((img * 255 + 0.5).astype(np.uint8)), (i * w, 0))
    draw = ImageDraw.Draw(sheet)
    for i in range(3):
        draw.polygon([(x + i * w, y) for x, y in convex_hull(np.array(frame["landmarks_2d"]))], outline=(0, 200, 0))
    sheet.save(os.path.join(a.out, "agreement.png"))
    json.dump(result, open(os.path.join(a.out, "agreement.json"), "w"), indent=1)
    print(json.dumps(result))


if __name__ == "__main__":
    main()
