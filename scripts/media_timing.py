#!/usr/bin/env python3
"""Sahara's volumetric path tracer against Mitsuba 3's `volpath` (`scalar_rgb` and `llvm_ad_rgb`), timed at
equal error on the media reference scenes of scripts/media_reference.py.

Each renderer renders each scene twice at the same resolution and samples per pixel with two seeds
(independent sampler, box filter, the same maximum depth, both cores). Its noise is measured from the
pair: σ² = spp · mean((a - b)²) / 2 over pixels and channels, a per-sample variance that needs no
reference (both renderers are held to the same images by the media reference test). Its time is the
faster run's render time (Sahara: the time it prints, without loading and tree build; Mitsuba:
`mi.render` until the image is evaluated, after an untimed warm-up that compiles `llvm_ad_rgb`'s
kernels). The speed-up at equal error against a Mitsuba variant V is (t_V σ_V²) / (t_S σ_S²): above 1,
Sahara reaches a given error sooner.

usage (Mitsuba 3.9.1 from PyPI: `python3 -m venv V && V/bin/pip install mitsuba==3.9.1 numpy`):
    V/bin/python scripts/media_timing.py [--sahara target/release/sahara] [--spp 64] [--size 256]
        [--only NAME,...]
"""
import argparse
import os
import re
import subprocess
import tempfile
import time

import numpy as np

import media_reference as ref


def sahara_run(binary, scene, size, spp, seed, out):
    """Renders and returns (image, render seconds)."""
    cmd = [binary, "render", scene, "--width", str(size), "--height", str(size), "--spp", str(spp),
           "--seed", str(seed), "--sampler", "independent", "--filter", "box", "-o", out]
    r = subprocess.run(cmd, capture_output=True, text=True, check=True)
    secs = float(re.search(r"([0-9.]+) s render", r.stderr).group(1))
    import mitsuba as mi
    return np.array(mi.Bitmap(out)).astype(np.float64)[..., :3], secs


def mitsuba_run(mi, name, case, tmp, size, spp, seed):
    if case["medium"]["kind"] == "colour":
        scene = mi.load_file(os.path.join(tmp, f"{name}.xml"))
    else:
        scene = ref.mitsuba_scene(mi, name, case, tmp, spp, seed, size)
    t = time.perf_counter()
    img = np.array(mi.render(scene, spp=spp, seed=seed)).astype(np.float64)
    return img[..., :3], time.perf_counter() - t, scene


def sigma2(a, b, spp):
    return spp * float(np.mean((a - b) ** 2)) / 2.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sahara", default=os.path.join(ref.ROOT, "target", "release", "sahara"))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--only", default="")
    args = ap.parse_args()
    import mitsuba as mi
    todo = ref.cases()
    if args.only:
        todo = {k: todo[k] for k in args.only.split(",")}
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, case in todo.items():
            if case["medium"]["kind"] == "grid":
                _, lo, hi = case["medium"]["bound"]
                ref.write_vol(os.path.join(tmp, f"{name}.vol"), ref.grid_blob(), lo, hi)
            if case["medium"]["kind"] == "colour":
                # One Mitsuba XML file (and its grids) that both renderers read.
                scene = os.path.join(tmp, f"{name}.xml")
                with open(scene, "w") as f:
                    f.write(ref.colour_blob_xml(case, tmp, args.spp, 0, args.size))
            else:
                scene = os.path.join(tmp, f"{name}.toml")
                with open(scene, "w") as f:
                    f.write(ref.sahara_scene(name, case))
            res = {}
            mi.set_variant("scalar_rgb")
            runs = [sahara_run(args.sahara, scene, args.size, args.spp, s, os.path.join(tmp, f"s{s}.exr"))
                    for s in (1, 2)]
            res["sahara"] = (runs[0][0], runs[1][0], min(runs[0][1], runs[1][1]))
            for v in ("scalar_rgb", "llvm_ad_rgb"):
                mi.set_variant(v)
                mitsuba_run(mi, name, case, tmp, args.size, args.spp, 0)  # warm-up
                a, ta, _ = mitsuba_run(mi, name, case, tmp, args.size, args.spp, 1)
                b, tb, _ = mitsuba_run(mi, name, case, tmp, args.size, args.spp, 2)
                res[v] = (a, b, min(ta, tb))
            out = {k: (t / args.spp, sigma2(a, b, args.spp), (a + b).reshape(-1, 3).mean(axis=0) / 2)
                   for k, (a, b, t) in res.items()}
            ts, ss, ms = out["sahara"]
            line = [name, f"{ts:.4f}", f"{np.sqrt(ss):.4f}"]
            for v in ("llvm_ad_rgb", "scalar_rgb"):
                tv, sv, mv = out[v]
                line += [f"{tv:.4f}", f"{np.sqrt(sv):.4f}", f"{tv * sv / (ts * ss):.2f}"]
            means = out["sahara"][2] / out["scalar_rgb"][2]
            rows.append(line + ["/".join(f"{x:.3f}" for x in means)])
            print(" ".join(line), flush=True)
    print(f"\n{args.size}x{args.size}, {args.spp} spp, two seeds each, s/spp = faster render / spp\n")
    print("| scene | Sahara s/spp | σ_S | `llvm_ad_rgb` s/spp | σ | speed-up | `scalar_rgb` s/spp | σ | speed-up "
          "| mean Sahara / scalar_rgb |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for r in rows:
        print("| `" + r[0] + "` | " + " | ".join(r[1:]) + " |")


if __name__ == "__main__":
    main()
