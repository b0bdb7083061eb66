#!/usr/bin/env python3
"""Sahara against Embree on the ray-casting protocol, in one run.

For every mesh, runs `sahara bench --json` and Embree's reference program
(../shared/bench/embree, built here when Embree is installed:
`apt-get install libembree-dev`) back to back, several rounds interleaved,
and prints markdown tables: hits and t-sums with the protocol's agreement
check, Mrays/s of both and the ratio Sahara / Embree (best of all rounds),
build times and memory.

Usage: scripts/compare_embree.py [--rounds N] [--runs N] [--builder B]
                                 [--meshes a,b,...] [--no-embree]
Run from the repository root after `cargo build --release`.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.environ.get("SAHARA_SCENES", os.path.join(ROOT, "..", "shared", "scenes"))
EMBREE_SRC = os.path.join(ROOT, "..", "shared", "bench", "embree")
SAHARA = os.path.join(ROOT, "target", "release", "sahara")
MESHES = ["bunny/bunny.obj", "dragon/dragon.obj", "sponza/sponza.obj",
          "teapot_stadium/teapot_stadium.obj", "cornell_box/cornell_box.obj"]
SETS = ["primary", "shadow", "diffuse", "random"]


def build_embree():
    """Path of the Embree benchmark, built into target/embree; None without Embree."""
    out = os.path.join(ROOT, "target", "embree")
    exe = os.path.join(out, "embree_bench")
    if os.path.exists(exe):
        return exe
    if not os.path.exists("/usr/include/embree3/rtcore.h") or shutil.which("gcc") is None:
        return None
    os.makedirs(out, exist_ok=True)
    subprocess.run(["sh", os.path.join(EMBREE_SRC, "build.sh"), out], check=True,
                   stdout=subprocess.DEVNULL)
    return exe


def run_embree(exe, mesh, runs):
    """Parse embree_bench's output: per set rays, hits, t_sum, best 1T/NT; builds; memory."""
    txt = subprocess.run([exe, mesh, "--runs", str(runs)], check=True, capture_output=True,
                         text=True).stdout
    r = {"sets": {}}
    for line in txt.splitlines():
        f = line.split()
        if f and f[0] in SETS + ["prim_p16", "prim_p8"] and len(f) >= 8 and f[1].isdigit():
            r["sets"][f[0]] = {"rays": int(f[1]), "hits": int(f[2]), "t_sum": float(f[3]),
                               "mrays_1t": float(f[4]), "mrays_all": float(f[7]),
                               "mrays_1t_cpu": float(f[10]) if len(f) > 10 else float(f[4])}
        m = re.match(r"build HIGH\s+\(all threads\): best ([\d.]+) ms.*bvh_bytes (\d+)", line)
        if m:
            r["build_ms"], r["memory_bytes"] = float(m.group(1)), int(m.group(2))
        m = re.match(r"build MEDIUM\s+\(all threads\): best ([\d.]+) ms", line)
        if m:
            r["build_medium_ms"] = float(m.group(1))
        m = re.match(r"scene for tracing: .*not counted: (\d+) bytes", line)
        if m:
            r["buffer_bytes"] = int(m.group(1))
    return r


def same_rays_check(exe, mesh, builder):
    """Secondary sets start at each tracer's own primary hits, so a few ulps
    of difference in a primary t move them. Trace Sahara's shadow and
    diffuse sets from Embree's primary hits instead: bit-identical rays."""
    hits = os.path.join(ROOT, "target", "embree", "primary.hits")
    subprocess.run([exe, mesh, "--runs", "1", "--no-build-times", "--sets", "primary",
                    "--dump", "primary", hits], check=True, capture_output=True)
    out = subprocess.run([SAHARA, "bench", mesh, "--json", "--runs", "1", "--builder", builder,
                          "--sets", "shadow,diffuse", "--primary-hits", hits],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)["sets"]


def run_sahara(mesh, runs, builder):
    out = subprocess.run([SAHARA, "bench", mesh, "--json", "--runs", str(runs), "--builder", builder],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def best(a, b):
    """Merge two rounds: keep the best throughput of each figure."""
    if a is None:
        return b
    for s, v in b["sets"].items():
        for k in ("mrays_1t", "mrays_all", "mrays_1t_cpu", "mrays_batch_1t_cpu", "mrays_packet_1t",
                  "mrays_packet_1t_cpu",
                  "mrays_packet16_1t", "mrays_packet16_1t_cpu"):
            if k in v:
                a["sets"][s][k] = max(a["sets"][s][k], v[k])
    for k in ("build_ms", "build_medium_ms"):
        if k in b:
            a[k] = min(a[k], b[k])
    return a


def agree(s, e):
    """The protocol's check: hits within 0.01% of rays, t-sums within 1e-4 relative."""
    hits_ok = abs(s["hits"] - e["hits"]) <= 1e-4 * e["rays"]
    t_ok = abs(s["t_sum"] - e["t_sum"]) <= 1e-4 * max(abs(e["t_sum"]), 1e-30)
    return hits_ok and t_ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--builder", default="sah")
    ap.add_argument("--meshes", default=",".join(MESHES))
    ap.add_argument("--no-embree", action="store_true")
    a = ap.parse_args()
    exe = None if a.no_embree else build_embree()
    if exe is None and not a.no_embree:
        print("Embree is not installed (apt-get install libembree-dev): Sahara only.", file=sys.stderr)
    load = open("/proc/loadavg").read().split()[:3]
    rows = []
    for m in a.meshes.split(","):
        path = os.path.join(SCENES, m)
        if not os.path.exists(path):
            print(f"skipping {path}: not found", file=sys.stderr)
            continue
        s_best = e_best = None
        for _ in range(a.rounds):
            if exe:
                e_best = best(e_best, run_embree(exe, path, a.runs))
            s_best = best(s_best, run_sahara(path, a.runs, a.builder))
        if e_best:
            s_best["same_rays"] = same_rays_check(exe, path, a.builder)
        rows.append((os.path.basename(os.path.dirname(path)), s_best, e_best))
        print(f"done {m}", file=sys.stderr)
    print(f"Load average at start: {' '.join(load)}; {a.rounds} rounds x best of {a.runs} runs; "
          f"Sahara builder `{a.builder}`.\n")
    print("1T: Mrays/s by the tracing thread's CPU time; batch 1T: Sahara's one batch call over "
          "the set on one thread; 2T: wall clock.\n")
    print("| mesh | set | rays | hits Sahara / Embree | t-sum Sahara / Embree | agree | "
          "Mrays/s 1T Sahara / Embree (ratio) | batch 1T Sahara / Embree (ratio) | "
          "Mrays/s 2T Sahara / Embree (ratio) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, s, e in rows:
        for k in SETS:
            sv = s["sets"][k]
            ev = e["sets"].get(k) if e else None
            if ev:
                print(f"| {name} | {k} | {sv['rays']:,} | {sv['hits']:,} / {ev['hits']:,} | "
                      f"{sv['t_sum']:.6f} / {ev['t_sum']:.6f} | {'yes' if agree(sv, ev) else '**no**'} | "
                      f"{sv['mrays_1t_cpu']:.2f} / {ev['mrays_1t_cpu']:.2f} ({sv['mrays_1t_cpu'] / ev['mrays_1t_cpu']:.2f}) | "
                      f"{sv.get('mrays_batch_1t_cpu', 0):.2f} / {ev['mrays_1t_cpu']:.2f} ({sv.get('mrays_batch_1t_cpu', 0) / ev['mrays_1t_cpu']:.2f}) | "
                      f"{sv['mrays_all']:.2f} / {ev['mrays_all']:.2f} ({sv['mrays_all'] / ev['mrays_all']:.2f}) |")
            else:
                print(f"| {name} | {k} | {sv['rays']:,} | {sv['hits']:,} | {sv['t_sum']:.6f} | - | "
                      f"{sv['mrays_1t_cpu']:.2f} | {sv.get('mrays_batch_1t_cpu', 0):.2f} | "
                      f"{sv['mrays_all']:.2f} |")
        for k, sv in (s.get("same_rays") or {}).items():
            if sv and e and not agree(s["sets"][k], e["sets"][k]):
                ev = e["sets"][k]
                print(f"| {name} | {k}, from Embree's primary hits | {sv['rays']:,} | "
                      f"{sv['hits']:,} / {ev['hits']:,} | {sv['t_sum']:.6f} / {ev['t_sum']:.6f} | "
                      f"{'yes' if agree(sv, ev) else '**no**'} | | | |")
        prim = s["sets"]["primary"]
        for sk, slabel in (("mrays_packet_1t_cpu", "8 (4x2)"), ("mrays_packet16_1t_cpu", "16 (4x4)")):
            p = prim.get(sk)
            for ek, label in (("prim_p8", "8"), ("prim_p16", "16")):
                if e and ek in e["sets"] and p is not None:
                    ev = e["sets"][ek]["mrays_1t_cpu"]
                    print(f"| {name} | primary packets: Sahara {slabel} / Embree {label} | | | | | "
                          f"{p:.2f} / {ev:.2f} ({p / ev:.2f}) | | |")
    print("\n| mesh | triangles | Sahara build ms | Embree HIGH / MEDIUM build ms | "
          "Sahara tree + triangles MB | Embree BVH MB (+ vertex/index buffers) | Sahara SAH cost |")
    print("|---|---|---|---|---|---|---|")
    for name, s, e in rows:
        eb = f"{e['build_ms']:.1f} / {e.get('build_medium_ms', float('nan')):.1f}" if e else "-"
        em = f"{e['memory_bytes'] / 1e6:.1f} (+{e.get('buffer_bytes', 0) / 1e6:.1f})" if e else "-"
        print(f"| {name} | {s['triangles']:,} | {s['build_ms']:.1f} | {eb} | "
              f"{s['memory_bytes'] / 1e6:.1f} | {em} | {s['sah_cost']:.1f} |")


if __name__ == "__main__":
    main()
