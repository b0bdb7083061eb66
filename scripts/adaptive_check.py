#!/usr/bin/env python3
"""Adaptive sampling against uniform sampling at equal samples.

Renders SCENE (default: the built-in Cornell box) once as a reference, then
with --noise-threshold T for each T, then uniformly with the same number of
samples per pixel on average, and prints the RMSE and the mean relative error
(the threshold's measure) of each against the reference, with render times.

Usage: scripts/adaptive_check.py [--scene FILE] [--size N] [--cap SPP]
                                 [--ref-spp SPP] [--thresholds a,b,...]
Needs numpy and OpenEXR (pip install numpy OpenEXR); run from the
repository root after `cargo build --release`.
"""
import argparse
import os
import re
import subprocess
import tempfile

import numpy as np
import OpenEXR

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SAHARA = os.path.join(ROOT, "target", "release", "sahara")


def render(scene, size, args, out):
    cmd = [SAHARA, "render"] + ([scene] if scene else []) + [
        "--width", str(size), "--height", str(size), "--filter", "box", "-o", out] + args
    log = subprocess.run(cmd, check=True, capture_output=True, text=True).stderr
    secs = float(re.search(r"([\d.]+) s render", log).group(1))
    return secs, log


def rgb(path):
    with OpenEXR.File(path) as f:
        p = f.parts[0].channels
        if "RGB" in p:
            return np.asarray(p["RGB"].pixels, dtype=np.float64)
        return np.stack([np.asarray(p[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)


def errors(img, ref):
    rmse = float(np.sqrt(np.mean((img - ref) ** 2)))
    rel = float(np.mean(np.abs(img - ref).sum(-1) / (1e-4 + np.sqrt(ref.sum(-1).clip(0)))))
    return rmse, rel


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--cap", type=int, default=256)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--thresholds", default="0.01,0.02,0.05")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp()
    ref_path = os.path.join(tmp, "ref.exr")
    render(a.scene, a.size, ["--spp", str(a.ref_spp), "--seed", "7"], ref_path)
    ref = rgb(ref_path)
    print("| noise threshold | mean spp | adaptive RMSE | uniform RMSE | adaptive rel. error | uniform rel. error | adaptive s | uniform s |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    for t in a.thresholds.split(","):
        out = os.path.join(tmp, f"a{t}.exr")
        secs_a, log = render(a.scene, a.size, ["--spp", str(a.cap), "--noise-threshold", t], out)
        samples = int(re.search(r"adaptive: (\d+) samples", log).group(1))
        spp = max(1, round(samples / (a.size * a.size)))
        uout = os.path.join(tmp, f"u{t}.exr")
        secs_u, _ = render(a.scene, a.size, ["--spp", str(spp)], uout)
        ea, eu = errors(rgb(out), ref), errors(rgb(uout), ref)
        print(f"| {t} | {samples / a.size ** 2:.1f} | {ea[0]:.5f} | {eu[0]:.5f} | {ea[1]:.4f} | {eu[1]:.4f} | {secs_a:.2f} | {secs_u:.2f} |")


if __name__ == "__main__":
    main()
