#!/usr/bin/env python3
"""docs/images/demo_sheet.png from a `make demo` output directory: for each expression sweep, four
frames (neutral, the middle, the target, 1.5 x the target) of compare_NNN.png (the model's render
left, the ground truth of the same expression and view right).

Usage: scripts/demo_sheet.py DEMO_OUT OUT.png   (needs Pillow: Debian python3-pil)
"""
import json
import os
import sys

from PIL import Image, ImageDraw


def main():
    demo, out = sys.argv[1], sys.argv[2]
    rows = []
    for sweep in ("sweep_jaw_open", "sweep_smile_left", "sweep_brow_raise_right"):
        frames = json.load(open(os.path.join(demo, sweep, "frames.json")))["frames"]
        n = len(frames)
        picks = sorted({0, (n - 1) // 3, 2 * (n - 1) // 3, n - 1})
        rows.append((sweep[len("sweep_"):], [Image.open(os.path.join(demo, sweep, "compare_%03d.png" % i)).convert("RGB")
                                             for i in picks]))
    w, h = rows[0][1][0].size
    label = 110
    sheet = Image.new("RGB", (label + len(rows[0][1]) * (w + 6), len(rows) * (h + 6)), "white")
    draw = ImageDraw.Draw(sheet)
    for r, (name, images) in enumerate(rows):
        y = r * (h + 6)
        draw.text((4, y + h // 2 - 6), name, fill="black")
        for c, im in enumerate(images):
            sheet.paste(im, (label + c * (w + 6), y))
    sheet.save(out)


if __name__ == "__main__":
    main()
