#!/usr/bin/env python3
"""CPU time to a clean image: each renderer renders one Mitsuba XML scene at increasing sample
counts, each image is compared with a converged reference, and the CPU time each renderer needs to
reach 5 % and 1 % relative MSE is read off a fit, with the ratios between the renderers.

Error: relative MSE, the mean over pixels and channels of (x - r)^2 / (r^2 + 0.01), where r is the
reference. The reference's own error is taken out: given as two independent halves A and B (two
seeds), the reference is their mean and its expected relative MSE is that of A against B over four.
With --reference-spp N, halves that do not exist yet are rendered first with Mitsuba 3 `llvm_ad_rgb`,
each the mean of N / 128 independent renders of 128 spp (one kernel over every sample of a frame
would not fit in memory at thousands of samples per pixel).
Time: the CPU time (user + system) of the whole renderer process, reading the scene and building
its trees included, which is what a user waits for. Fit: error = c / spp over the sample counts
rendered (the variance of a Monte Carlo estimate falls as 1 / spp), time = a + b spp; the time to
error e is then a + b c / e. The renderers run one after the other at each sample count
(interleaved), each on all cores.

Renderers (repeatable --renderer):
    sahara[:ARGS]      `sahara render SCENE -D spp=N -o OUT.exr ARGS` ($SAHARA, else
                       target/release/sahara), e.g. `sahara:--light-sampler power`
    mitsuba[:VARIANT]  Mitsuba 3 in this Python (`import mitsuba`), VARIANT default llvm_ad_rgb;
                       its JIT kernels are cached after a first, untimed render

usage (the Python that has Mitsuba 3 and numpy):
    V/bin/python scripts/clean_time.py SCENE.xml --reference A.exr B.exr [--spp 4,16,64]
        [--reference-spp N] [--renderer sahara] [--renderer 'sahara:--light-sampler power']
        [--renderer mitsuba] [--work DIR] [--json OUT.json]
"""
import argparse
import json
import os
import resource
import shlex
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_exr(path):
    import mitsuba as mi

    if not mi.variant():
        mi.set_variant("scalar_rgb")
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def rel_mse(x, r):
    return float(np.mean((x - r) ** 2 / (r * r + 0.01)))


MITSUBA_CHILD = r"""
import sys, mitsuba as mi
variant, scene, spp, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
mi.set_variant(variant)
s = mi.load_file(scene)
mi.Bitmap(mi.render(s, spp=spp, seed=7)).write(out)
"""

# A reference half: the mean of independent llvm_ad_rgb renders of CHUNK spp, seeds first, first + 1, ...
REFERENCE_CHILD = r"""
import os, sys, numpy as np, mitsuba as mi
scene, spp, chunk, first, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
mi.set_variant("llvm_ad_rgb")
s = mi.load_file(scene)
chunk = min(chunk, spp)
runs = spp // chunk
acc = sum(np.array(mi.render(s, spp=chunk, seed=first + k), dtype=np.float64) for k in range(runs))
tmp = out + ".part.exr"
mi.Bitmap((acc / runs).astype(np.float32)).write(tmp)
os.replace(tmp, out)
"""
REFERENCE_CHUNK = 128


def make_reference(scene, halves, spp):
    """Renders the halves of a reference that are missing (two independent sets of seeds)."""
    for k, out in enumerate(halves):
        if os.path.exists(out):
            continue
        print(f"rendering reference half {out}: {spp} spp of llvm_ad_rgb", flush=True)
        first = 1000 + k * 100000
        cmd = [sys.executable, "-c", REFERENCE_CHILD, scene, str(spp), str(REFERENCE_CHUNK), str(first), out]
        p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if p.returncode != 0:
            sys.exit(f"{shlex.join(cmd)} failed:\n{p.stderr}")


def command(renderer, scene, spp, out):
    kind, _, arg = renderer.partition(":")
    if kind == "sahara":
        exe = os.environ.get("SAHARA", os.path.join(ROOT, "target", "release", "sahara"))
        return [exe, "render", scene, "-D", f"spp={spp}", "-o", out] + shlex.split(arg)
    if kind == "mitsuba":
        return [sys.executable, "-c", MITSUBA_CHILD, arg or "llvm_ad_rgb", scene, str(spp), out]
    sys.exit(f"unknown renderer {renderer!r}: sahara[:ARGS] or mitsuba[:VARIANT]")


def cpu_run(cmd):
    """Runs cmd; returns its CPU time (user + system, seconds)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        sys.exit(f"{shlex.join(cmd)} failed:\n{p.stderr}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--reference", nargs=2, required=True, metavar=("A", "B"))
    ap.add_argument("--reference-spp", type=int, default=None,
                    help="render the missing reference halves with this many spp each")
    ap.add_argument("--spp", default="4,16,64")
    ap.add_argument("--renderer", action="append")
    ap.add_argument("--work", default=None)
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    renderers = a.renderer or ["sahara", "mitsuba"]
    spps = [int(s) for s in a.spp.split(",")]
    work = a.work or tempfile.mkdtemp(prefix="clean_time_")
    os.makedirs(work, exist_ok=True)
    if a.reference_spp:
        make_reference(a.scene, a.reference, a.reference_spp)
    ra, rb = read_exr(a.reference[0]), read_exr(a.reference[1])
    ref = 0.5 * (ra + rb)
    ref_err = rel_mse(ra, rb) / 4.0
    print(f"reference: relative MSE of its halves {4 * ref_err:.3g}; its own about {ref_err:.3g}")
    # Untimed warm-up: Mitsuba's kernels compiled and cached, files in the page cache.
    for r in renderers:
        cpu_run(command(r, a.scene, spps[0], os.path.join(work, "warm.exr")))
    rows = {r: [] for r in renderers}
    for spp in spps:
        for r in renderers:
            out = os.path.join(work, f"{len(rows[r])}-{renderers.index(r)}.exr")
            t = cpu_run(command(r, a.scene, spp, out))
            e = max(rel_mse(read_exr(out), ref) - ref_err, 1e-12)
            rows[r].append((spp, t, e))
            print(f"{r:40s} spp {spp:5d}: cpu {t:8.2f} s  relMSE {e:.4g}", flush=True)
    result = {}
    for r, pts in rows.items():
        s = np.array([p[0] for p in pts], float)
        t = np.array([p[1] for p in pts], float)
        e = np.array([p[2] for p in pts], float)
        c = float(np.exp(np.mean(np.log(e * s))))  # error = c / spp, fitted in log space
        b, a0 = np.polyfit(s, t, 1) if len(s) > 1 else (t[0] / s[0], 0.0)
        to = {f"{int(100 * x)}%": float(a0 + b * c / x) for x in (0.05, 0.01)}
        result[r] = {"points": pts, "c": c, "fixed_s": float(a0), "s_per_spp": float(b), "time_to": to}
    base = renderers[-1]
    print(f"\nCPU seconds to relative MSE (fit error = c/spp, time = a + b spp); ratio: {base}'s time / the renderer's")
    print(f"{'renderer':40s} {'a (s)':>8s} {'b (s/spp)':>10s} {'c':>9s} {'5 %':>9s} {'1 %':>9s} {'x at 5 %':>9s} {'x at 1 %':>9s}")
    for r, v in result.items():
        t5, t1 = v["time_to"]["5%"], v["time_to"]["1%"]
        b5, b1 = result[base]["time_to"]["5%"], result[base]["time_to"]["1%"]
        print(f"{r:40s} {v['fixed_s']:8.2f} {v['s_per_spp']:10.4f} {v['c']:9.4g} {t5:9.1f} {t1:9.1f} {b5 / t5:9.2f} {b1 / t1:9.2f}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
