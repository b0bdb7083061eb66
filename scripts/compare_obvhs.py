#!/usr/bin/env python3
"""Sahara against the obvhs crate (CWBVH and BVH2) on the protocol's rays.

For every mesh, `sahara bench --dump-rays` writes the four ray sets once;
then, in interleaved rounds, `sahara bench --rays FILE` and `bench-obvhs`
(crates/bench-obvhs) trace the same files on one thread. obvhs is built
twice: for the native CPU (`-C target-cpu=native`, as its authors advise)
and for baseline x86-64 (as Sahara's release binary is, which picks its
SIMD level at run time). Prints markdown tables: hits and t-sums of each
tracer with the protocol's agreement check, and the best Mrays/s by thread
CPU time with the ratios Sahara / obvhs.

Usage: scripts/compare_obvhs.py [--rounds N] [--runs N] [--meshes a,b,...]
                                [--preset fast|medium|slow|very-slow]
Run from the repository root after `cargo build --release`.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.environ.get("SAHARA_SCENES", os.path.join(ROOT, "..", "shared", "scenes"))
SAHARA = os.path.join(ROOT, "target", "release", "sahara")
MESHES = ["bunny/bunny.obj", "dragon/dragon.obj", "sponza/sponza.obj",
          "teapot_stadium/teapot_stadium.obj", "cornell_box/cornell_box.obj"]
SETS = ["primary", "shadow", "diffuse", "random"]


def build_obvhs():
    """Paths of bench-obvhs built for the native CPU and for baseline x86-64."""
    exes = {}
    for kind, flags, target in [("native", "-C target-cpu=native", "obvhs-native"),
                                ("baseline", "", "obvhs-baseline")]:
        env = dict(os.environ, RUSTFLAGS=flags)
        tdir = os.path.join(ROOT, "target", target)
        subprocess.run(["cargo", "build", "--release", "-q", "-p", "bench-obvhs",
                        "--target-dir", tdir], check=True, env=env, cwd=ROOT)
        exes[kind] = os.path.join(tdir, "release", "bench-obvhs")
    return exes


def agree(a, b):
    """The protocol's check: hits within 0.01% of the rays, t-sums within 1e-4 relative."""
    if abs(a["hits"] - b["hits"]) > 1e-4 * a["rays"]:
        return False
    return abs(a["t_sum"] - b["t_sum"]) <= 1e-4 * max(abs(a["t_sum"]), 1e-9)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--meshes", default=",".join(MESHES))
    ap.add_argument("--preset", default="slow")
    args = ap.parse_args()
    if not os.path.exists(SAHARA):
        sys.exit(f"{SAHARA} is missing: run `cargo build --release` first")
    exes = build_obvhs()
    tracers = ["sahara", "sahara_batch", "cwbvh_native", "bvh2_native", "cwbvh_baseline",
               "bvh2_baseline"]
    best = {}    # (mesh, set, tracer) -> best Mrays/s
    result = {}  # (mesh, set, tracer) -> hits/t_sum/rays
    with tempfile.TemporaryDirectory() as tmp:
        meshes = [m for m in args.meshes.split(",") if m]
        files = {}
        for m in meshes:
            path = os.path.join(SCENES, m)
            cmd = [SAHARA, "bench", path, "--runs", "1", "--json"]
            for s in SETS:
                f = os.path.join(tmp, f"{os.path.basename(m)}.{s}.rays")
                cmd += ["--dump-rays", s, f]
                files[(m, s)] = f
            subprocess.run(cmd, check=True, capture_output=True)
        for rnd in range(args.rounds):
            for m in meshes:
                path = os.path.join(SCENES, m)
                for s in SETS:
                    f = files[(m, s)]
                    any_hit = ["--any-hit"] if s == "shadow" else []
                    out = subprocess.run([SAHARA, "bench", path, "--rays", f, "--json", "--threads",
                                          "1", "--runs", str(args.runs)] + any_hit, check=True,
                                         capture_output=True, text=True).stdout
                    r = json.loads(out)["sets"]["file"]
                    for t, key in [("sahara", "mrays_1t_cpu"), ("sahara_batch", "mrays_batch_1t_cpu")]:
                        result[(m, s, t)] = r
                        best[(m, s, t)] = max(best.get((m, s, t), 0.0), r[key])
                    for kind, exe in exes.items():
                        for layout in ["cwbvh", "bvh2"]:
                            out = subprocess.run([exe, path, f, "--layout", layout, "--preset",
                                                  args.preset, "--runs", str(args.runs)] + any_hit,
                                                 check=True, capture_output=True, text=True).stdout
                            r = json.loads(out)
                            t = f"{layout}_{kind}"
                            result[(m, s, t)] = r
                            best[(m, s, t)] = max(best.get((m, s, t), 0.0), r["mrays_1t_cpu"])
            print(f"round {rnd + 1} of {args.rounds} done", file=sys.stderr)
    print(f"obvhs preset `{args.preset}`; best of {args.rounds} rounds x {args.runs} runs, "
          "Mrays/s on one thread by CPU time\n")
    print("| mesh | set | hits Sahara / CWBVH / BVH2 | agree CWBVH, BVH2 | Sahara | Sahara batch "
          "| CWBVH native | BVH2 native | CWBVH x86-64 | BVH2 x86-64 | Sahara / best native "
          "| Sahara / best x86-64 |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for m in meshes:
        name = os.path.basename(m).rsplit(".", 1)[0]
        for s in SETS:
            r = {t: result[(m, s, t)] for t in tracers}
            b = {t: best[(m, s, t)] for t in tracers}
            yes = lambda t: "yes" if agree(r["sahara"], r[t]) else "**no**"
            sahara = max(b["sahara"], b["sahara_batch"])
            nat = max(b["cwbvh_native"], b["bvh2_native"])
            base = max(b["cwbvh_baseline"], b["bvh2_baseline"])
            print(f"| {name} | {s} | {r['sahara']['hits']:,} / {r['cwbvh_native']['hits']:,} / "
                  f"{r['bvh2_native']['hits']:,} | {yes('cwbvh_native')}, {yes('bvh2_native')} | "
                  f"{b['sahara']:.2f} | {b['sahara_batch']:.2f} | {b['cwbvh_native']:.2f} | "
                  f"{b['bvh2_native']:.2f} | {b['cwbvh_baseline']:.2f} | {b['bvh2_baseline']:.2f} | "
                  f"{sahara / nat:.2f} | {sahara / base:.2f} |")


if __name__ == "__main__":
    main()
