#!/usr/bin/python3
"""Generates tests/fixtures/ssim/: small image pairs and their PSNR / SSIM as computed by an
independent implementation, Debian's python3-skimage (skimage.metrics). Run once; the outputs are
committed and the C++ test (src/icef/eval/metrics_test.cc) reads them without Python.

    /usr/bin/python3 scripts/make_ssim_fixture.py     # needs: apt-get install python3-skimage

Conventions (the ones icef::eval::Ssim follows): images in [0, 1] (8-bit PNG / 255), RGB,
structural_similarity(gaussian_weights=True, sigma=1.5, use_sample_covariance=False,
data_range=1, channel_axis=-1) -- an 11-tap Gaussian window, K1 = 0.01, K2 = 0.03, the SSIM map
averaged over the pixels at least 5 from the border and over the channels. The masked variants
average the same SSIM map (full=True) only over the interior pixels where mask > 0.5, and PSNR
over the masked pixels.
"""
import json
import os

import imageio
import numpy as np
import scipy
import skimage
from skimage.metrics import peak_signal_noise_ratio, structural_similarity

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures", "ssim")


def to_u8(x):
    return np.clip(np.round(x * 255.0), 0, 255).astype(np.uint8)


def make_pairs(rng):
    h, w = 24, 32
    yy, xx = np.mgrid[0:h, 0:w] / np.array([h, w]).reshape(2, 1, 1)
    base = np.stack([xx, yy, 0.5 + 0.4 * np.sin(6 * xx + 3 * yy)], axis=-1)
    noisy = base + rng.normal(0, 0.05, base.shape)
    pairs = [("gradient_noise", base, noisy)]

    tex = rng.uniform(0, 1, (20, 28, 3))
    shifted = np.roll(tex, 1, axis=1) * 0.8 + 0.1
    pairs.append(("texture_shift", tex, shifted))

    checker = ((np.indices((30, 26)).sum(axis=0) // 3) % 2).astype(float)
    a = np.stack([checker, 1 - checker, 0.5 * checker + 0.25], axis=-1)
    k = np.array([0.25, 0.5, 0.25])
    blur = a.copy()
    for axis in (0, 1):
        blur = np.apply_along_axis(lambda v: np.convolve(np.pad(v, 1, mode="edge"), k, mode="valid"), axis, blur)
    pairs.append(("checker_blur", a, blur))

    face = skimage.data.astronaut()[40:104:2, 160:224:2] / 255.0  # 32x32 crop of the face
    jitter = face + rng.normal(0, 0.02, face.shape) - 0.03
    pairs.append(("astronaut_jitter", face, jitter))
    return pairs


def main():
    rng = np.random.RandomState(20240611)
    os.makedirs(OUT, exist_ok=True)
    entries = []
    for name, a, b in make_pairs(rng):
        a8, b8 = to_u8(a), to_u8(b)
        imageio.imwrite(os.path.join(OUT, name + "_a.png"), a8)
        imageio.imwrite(os.path.join(OUT, name + "_b.png"), b8)
        af, bf = a8.astype(np.float64) / 255.0, b8.astype(np.float64) / 255.0
        ssim, smap = structural_similarity(af, bf, gaussian_weights=True, sigma=1.5, use_sample_covariance=False,
                                           data_range=1.0, channel_axis=-1, full=True)
        psnr = peak_signal_noise_ratio(af, bf, data_range=1.0)
        # A mask: an ellipse of foreground, as a 1-channel PNG.
        h, w = a8.shape[:2]
        yy, xx = np.mgrid[0:h, 0:w]
        mask = (((yy - h * 0.55) / (h * 0.4)) ** 2 + ((xx - w * 0.45) / (w * 0.35)) ** 2) <= 1.0
        imageio.imwrite(os.path.join(OUT, name + "_mask.png"), (mask * 255).astype(np.uint8))
        pad = 5  # (win_size - 1) // 2, as skimage crops the SSIM map
        inner = np.zeros_like(mask)
        inner[pad:h - pad, pad:w - pad] = True
        sel = mask & inner
        ssim_masked = float(smap[sel].mean())  # mean over masked interior pixels and channels
        mse_masked = float(((af - bf) ** 2)[mask].mean())
        entries.append({
            "name": name,
            "a": name + "_a.png",
            "b": name + "_b.png",
            "mask": name + "_mask.png",
            "psnr": float(psnr),
            "ssim": float(ssim),
            "psnr_masked": float(10.0 * np.log10(1.0 / mse_masked)),
            "ssim_masked": ssim_masked,
        })
    meta = {
        "generator": "scripts/make_ssim_fixture.py",
        "skimage": skimage.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "ssim_call": "structural_similarity(a, b, gaussian_weights=True, sigma=1.5, use_sample_covariance=False, "
                     "data_range=1.0, channel_axis=-1)",
        "pairs": entries,
    }
    with open(os.path.join(OUT, "expected.json"), "w") as f:
        json.dump(meta, f, indent=2)
        f.write("\n")
    print("wrote", len(entries), "pairs to", os.path.normpath(OUT))


if __name__ == "__main__":
    main()
