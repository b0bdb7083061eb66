#!/usr/bin/env python3
"""Adaptive sampling against uniform sampling at equal samples, or at equal
CPU time.

Renders SCENE (default: the built-in Cornell box) once as a reference (or
reads --ref), then with --noise-threshold T for each T, then uniformly with
the same number of samples per pixel on average, and prints the RMSE and the
mean relative error (the threshold's measure) of each against the reference,
with render times. With --equal-time it renders uniformly a second time, with
the samples per pixel that take the adaptive render's CPU time (scaled from
the first uniform render's), and prints that render's RMSE too.

RMSE is RMSE* when the reference has a `variance` layer (this script renders
its reference with one, sampled independently): the reference's own noise
taken out, sqrt(max(0, MSE - mean variance of the reference)). --plain gives
the plain RMSE (for a reference from a low-discrepancy sampler, whose
variance layer overstates its noise).

Usage: scripts/adaptive_check.py [--scene FILE] [--size N] [--cap SPP]
                                 [--ref-spp SPP | --ref EXR] [--equal-time]
                                 [--plain] [--thresholds a,b,...]
                                 [--args "more render arguments"]
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
SAHARA = os.environ.get("SAHARA_BIN", os.path.join(ROOT, "target", "release", "sahara"))


def render(scene, size, args, out):
    """-> (wall seconds, CPU seconds, log)"""
    cmd = [SAHARA, "render"] + ([scene] if scene else []) + [
        "--width", str(size), "--height", str(size), "--filter", "box", "-o", out] + args
    log = subprocess.run(cmd, check=True, capture_output=True, text=True).stderr
    secs = float(re.search(r"([\d.]+) s render", log).group(1))
    cpu = float(re.search(r"([\d.]+) CPU s", log).group(1))
    return secs, cpu, log


def rgb(path, layer="RGB"):
    with OpenEXR.File(path) as f:
        p = f.parts[0].channels
        if layer in p:
            return np.asarray(p[layer].pixels, dtype=np.float64)
        if layer != "RGB":
            return None
        return np.stack([np.asarray(p[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)


def errors(img, ref, mse_ref):
    rmse = float(np.sqrt(max(0.0, np.mean((img - ref) ** 2) - mse_ref)))
    rel = float(np.mean(np.abs(img - ref).sum(-1) / (1e-4 + np.sqrt(ref.sum(-1).clip(0)))))
    return rmse, rel


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--cap", type=int, default=256)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--thresholds", default="0.01,0.02,0.05")
    ap.add_argument("--ref", help="a reference EXR rendered before (at --size)")
    ap.add_argument("--equal-time", action="store_true")
    ap.add_argument("--plain", action="store_true")
    ap.add_argument("--args", default="", help="more arguments of the adaptive and uniform renders")
    a = ap.parse_args()
    more = a.args.split()
    tmp = tempfile.mkdtemp()
    ref_path = a.ref or os.path.join(tmp, "ref.exr")
    if not a.ref:
        render(a.scene, a.size, ["--spp", str(a.ref_spp), "--seed", "7", "--aov", "variance", "--sampler", "independent"], ref_path)
    ref = rgb(ref_path)
    var = rgb(ref_path, "variance")
    mse_ref = 0.0 if var is None or a.plain else float(np.mean(var))
    head = "| noise threshold | mean spp | adaptive RMSE | uniform RMSE | adaptive rel. error | uniform rel. error | adaptive CPU s | uniform CPU s |"
    if a.equal_time:
        head += " equal-time spp | its CPU s | its RMSE | adaptive / equal-time RMSE |"
    print(head)
    print("|---:" * (head.count("|") - 1) + "|")
    for t in a.thresholds.split(","):
        out = os.path.join(tmp, f"a{t}.exr")
        _, cpu_a, log = render(a.scene, a.size, ["--spp", str(a.cap), "--noise-threshold", t] + more, out)
        samples = int(re.search(r"adaptive: (\d+) samples", log).group(1))
        spp = max(1, round(samples / (a.size * a.size)))
        uout = os.path.join(tmp, f"u{t}.exr")
        _, cpu_u, _ = render(a.scene, a.size, ["--spp", str(spp)] + more, uout)
        ea, eu = errors(rgb(out), ref, mse_ref), errors(rgb(uout), ref, mse_ref)
        row = f"| {t} | {samples / a.size ** 2:.1f} | {ea[0]:.5f} | {eu[0]:.5f} | {ea[1]:.4f} | {eu[1]:.4f} | {cpu_a:.2f} | {cpu_u:.2f} |"
        if a.equal_time:
            spp_t = max(1, round(spp * cpu_a / cpu_u))
            tout = os.path.join(tmp, f"t{t}.exr")
            _, cpu_t, _ = render(a.scene, a.size, ["--spp", str(spp_t)] + more, tout)
            et = errors(rgb(tout), ref, mse_ref)
            row += f" {spp_t} | {cpu_t:.2f} | {et[0]:.5f} | {ea[0] / et[0]:.3f} |"
        print(row, flush=True)


if __name__ == "__main__":
    main()
