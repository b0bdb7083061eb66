#!/usr/bin/env python3
"""The pictures and figures of docs/clean-image.md.

Renders the repository's glossy-and-glass Cornell box (path tracer, box
filter) five ways: 16 samples per pixel plain and denoised, 128 plain,
adaptive sampling with a cap of 128, and a converged reference; writes the
PNGs the page shows into docs/images/ (the adaptive render's samples per
pixel as a heat map) and prints each image's RMSE against the reference
with its render time and CPU time.

Usage: scripts/clean_image_pictures.py [--size N] [--ref-spp SPP]
                                       [--threshold T] [--ref FILE.exr]
Needs numpy and OpenEXR (pip install numpy OpenEXR) and Open Image Denoise
(see docs/clean-image.md); run from the repository root after
`cargo build --release`. --ref reuses a reference rendered before (with the
same size).
"""
import argparse
import os
import re
import struct
import subprocess
import tempfile
import zlib

import numpy as np
import OpenEXR

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SAHARA = os.path.join(ROOT, "target", "release", "sahara")
SCENE = os.path.join(ROOT, "scenes", "cornell_glossy_glass.toml")
IMAGES = os.path.join(ROOT, "docs", "images")


def render(size, args, out):
    cmd = [SAHARA, "render", SCENE, "--width", str(size), "--height", str(size),
           "--integrator", "path", "--filter", "box", "-o", out] + args
    print("  " + " ".join(["sahara"] + cmd[1:]).replace(ROOT + "/", ""))
    log = subprocess.run(cmd, check=True, capture_output=True, text=True).stderr
    secs = float(re.search(r"([\d.]+) s render", log).group(1))
    cpu = float(re.search(r"([\d.]+) CPU s", log).group(1))
    return secs, cpu


def layers(path):
    with OpenEXR.File(path) as f:
        return {k: np.asarray(v.pixels, dtype=np.float64) for k, v in f.parts[0].channels.items()}


def rgb(path):
    p = layers(path)
    if "RGB" in p:
        return p["RGB"]
    return np.stack([p[c] for c in "RGB"], axis=-1)


def write_png(path, img):
    """An 8-bit RGB PNG of `img` (h x w x 3 in [0, 1], already display-encoded)."""
    h, w, _ = img.shape
    rows = (np.clip(img, 0, 1) * 255 + 0.5).astype(np.uint8)
    raw = b"".join(b"\x00" + rows[y].tobytes() for y in range(h))

    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def heat(t):
    """Black, blue, red, yellow, white as t goes from 0 to 1."""
    stops = np.array([[0, 0, 0], [0.1, 0.2, 0.9], [0.9, 0.1, 0.1], [1, 0.9, 0.1], [1, 1, 1]])
    x = np.clip(t, 0, 1) * (len(stops) - 1)
    i = np.minimum(x.astype(int), len(stops) - 2)
    f = (x - i)[..., None]
    return stops[i] * (1 - f) + stops[i + 1] * f


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=320)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--threshold", type=float, default=0.05)
    ap.add_argument("--ref")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp()
    ref_path = a.ref or os.path.join(tmp, "ref.exr")
    if not a.ref:
        render(a.size, ["--spp", str(a.ref_spp), "--seed", "7"], ref_path)
    ref = rgb(ref_path)
    runs = [
        ("noisy16", "16 spp", ["--spp", "16"]),
        ("denoised16", "16 spp, --denoise", ["--spp", "16", "--denoise"]),
        ("plain128", "128 spp", ["--spp", "128"]),
        ("adaptive", f"--noise-threshold {a.threshold}, cap 128 spp",
         ["--spp", "128", "--noise-threshold", str(a.threshold)]),
    ]
    print("| render | RMSE | render s | CPU s |")
    print("| --- | ---: | ---: | ---: |")
    for name, label, args in runs:
        exr = os.path.join(tmp, name + ".exr")
        secs, cpu = render(a.size, args, exr)
        img = rgb(exr)
        rmse = float(np.sqrt(np.mean((img - ref) ** 2)))
        print(f"| {label} | {rmse:.4f} | {secs:.2f} | {cpu:.2f} |")
        png = os.path.join(IMAGES, f"clean-{name}.png")
        subprocess.run([SAHARA, "render", SCENE, "--width", str(a.size), "--height", str(a.size),
                        "--integrator", "path", "--filter", "box", "-o", png] + args,
                       check=True, capture_output=True)
        if name == "adaptive":
            spp = layers(exr)["samples.Y"]
            write_png(os.path.join(IMAGES, "clean-adaptive-samples.png"), heat(spp / 128.0))
            print(f"  adaptive: {spp.mean():.1f} samples per pixel on average")


if __name__ == "__main__":
    main()
