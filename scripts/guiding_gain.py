#!/usr/bin/env python3
"""Path guiding's gain on a scene at equal error, without a reference: renders the scene with
`--guiding on` and `--guiding off`, each with two seeds, interleaved; each setting's relative
variance is half the relative MSE between its two seeds' images (the mean over pixels and channels
of (a - b)^2 / 2 / (m^2 + 0.01), m the mean of all four images), and its CPU time (user + system,
the whole process) the mean of its two renders. The CPU time to equal error scales as time x
variance, so the gain is (t_off v_off) / (t_on v_on): above 1, guiding reaches a given error sooner.
An unbiased estimator is assumed (guiding's is; see the tests).

usage (a Python with numpy and Mitsuba 3, for reading EXR):
    V/bin/python scripts/guiding_gain.py SCENE --spp N [--args '...'] [--work DIR]
"""
import argparse
import os
import shlex
import tempfile

import numpy as np

# The same EXR reading and CPU accounting as the time-to-clean-image script.
from clean_time import cpu_run, read_exr

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--args", default="", help="more `sahara render` arguments")
    ap.add_argument("--work", default=None)
    a = ap.parse_args()
    work = a.work or tempfile.mkdtemp(prefix="guiding_gain_")
    os.makedirs(work, exist_ok=True)
    exe = os.environ.get("SAHARA", os.path.join(ROOT, "target", "release", "sahara"))
    times, images = {}, {}
    for seed in (1, 2):
        for g in ("off", "on"):
            out = os.path.join(work, f"{g}_{seed}.exr")
            cmd = [exe, "render", a.scene, "--spp", str(a.spp), "--seed", str(seed),
                   "--guiding", g, "-o", out] + shlex.split(a.args)
            times.setdefault(g, []).append(cpu_run(cmd))
            images.setdefault(g, []).append(read_exr(out))
    m = sum(sum(v) for v in images.values()) / 4.0
    res = {}
    for g in ("off", "on"):
        x, y = images[g]
        v = float(np.mean((x - y) ** 2 / 2.0 / (m * m + 0.01)))
        t = float(np.mean(times[g]))
        mean = x.mean(axis=(0, 1)) + y.mean(axis=(0, 1))
        res[g] = (t, v, mean)
        print(f"guiding {g:3}: {a.spp} spp, cpu {t:7.2f} s, relative variance {v:.4g}")
    ratio = res["on"][2] / res["off"][2]
    gain = (res["off"][0] * res["off"][1]) / (res["on"][0] * res["on"][1])
    print(f"mean on/off per channel {np.round(ratio, 3)}; CPU time to equal error off/on: {gain:.2f}x")


if __name__ == "__main__":
    main()
