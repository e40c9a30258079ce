#!/usr/bin/env python3
"""Converts the official LPIPS v0.1 AlexNet weights into ICEF's LPIPS weights file
(format: docs/evaluation.md and src/icef/eval/lpips.h).

The official weights are two PyTorch state dicts, neither shipped by any package ICEF installs:
  * torchvision's ImageNet AlexNet: alexnet-owt-7be5be79.pth
    (keys features.{0,3,6,8,10}.{weight,bias})
  * LPIPS's linear heads: lpips/weights/v0.1/alex.pth from github.com/richzhang/PerceptualSimilarity
    (keys lin{0..4}.model.1.weight, or lin{i}.model.0.weight without dropout)

    python3 scripts/convert_lpips_weights.py --alexnet alexnet-owt-7be5be79.pth \\
        --lin alex.pth --out lpips_alex_v0.1.bin
    icef eval MODEL DATASET --lpips-weights lpips_alex_v0.1.bin ...

Needs torch (only to unpickle the .pth files) and numpy.
"""
import argparse
import struct
import sys

import numpy as np

MAGIC = b"ICEFLPIP"
VERSION = 1
ALEX_CONV_KEYS = [0, 3, 6, 8, 10]  # torchvision alexnet.features indices of conv1..conv5
KERNELS = [11, 5, 3, 3, 3]


def write_weights(path, convs, lins):
    """convs: 5 (weight [O, I, kh, kw], bias [O]) float arrays; lins: 5 arrays [1, C, 1, 1]."""
    tensors = []
    cin = 3
    for i, (w, b) in enumerate(convs):
        w = np.ascontiguousarray(w, dtype="<f4")
        b = np.ascontiguousarray(b, dtype="<f4")
        if w.ndim != 4 or w.shape[1] != cin or w.shape[2:] != (KERNELS[i], KERNELS[i]) or b.shape != (w.shape[0],):
            sys.exit(f"conv{i + 1}: unexpected shapes weight {w.shape}, bias {b.shape}")
        tensors += [(f"conv{i + 1}.weight", w), (f"conv{i + 1}.bias", b)]
        cin = w.shape[0]
    for i, lin in enumerate(lins):
        lin = np.ascontiguousarray(lin, dtype="<f4").reshape(1, -1, 1, 1)
        if lin.shape[1] != convs[i][0].shape[0]:
            sys.exit(f"lin{i}: {lin.shape[1]} channels, conv{i + 1} has {convs[i][0].shape[0]}")
        tensors.append((f"lin{i}.weight", lin))
    with open(path, "wb") as f:
        f.write(MAGIC + struct.pack("<II", VERSION, len(tensors)))
        for name, t in tensors:
            raw = name.encode()
            f.write(struct.pack("<I", len(raw)) + raw + struct.pack("<I", t.ndim))
            f.write(struct.pack("<%dI" % t.ndim, *t.shape))
            f.write(t.tobytes())


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--alexnet", required=True, help="torchvision AlexNet state dict (.pth)")
    parser.add_argument("--lin", required=True, help="LPIPS v0.1 alex.pth (linear heads)")
    parser.add_argument("--out", default="lpips_alex_v0.1.bin", help="output file")
    args = parser.parse_args()
    import torch  # only needed to read the official files

    alex = torch.load(args.alexnet, map_location="cpu")
    lin = torch.load(args.lin, map_location="cpu")
    convs = []
    for k in ALEX_CONV_KEYS:
        w, b = alex.get(f"features.{k}.weight"), alex.get(f"features.{k}.bias")
        if w is None or b is None:
            sys.exit(f"{args.alexnet}: missing features.{k}.weight/bias (not a torchvision AlexNet state dict?)")
        convs.append((w.numpy(), b.numpy()))
    lins = []
    for i in range(5):
        t = lin.get(f"lin{i}.model.1.weight", lin.get(f"lin{i}.model.0.weight"))
        if t is None:
            sys.exit(f"{args.lin}: missing lin{i}.model.1.weight (not an LPIPS v0.1 alex.pth?)")
        lins.append(t.numpy())
    write_weights(args.out, convs, lins)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
