#!/usr/bin/env python3
"""Sahara against Embree on the ray-casting protocol, in one run.

For every mesh, runs `sahara bench --json` and Embree's reference program
(../shared/bench/embree, built here when Embree is installed:
`apt-get install libembree-dev`) back to back, several rounds interleaved,
and prints markdown tables: hits and t-sums with the protocol's agreement
check, Mrays/s of both and the ratio Sahara / Embree (best of all rounds),
build times and memory.

Usage: scripts/compare_embree.py [--rounds N] [--runs N] [--accel kd,bvh]
                                 [--builder B] [--bvh-builder B]
                                 [--meshes a,b,...] [--no-embree]

With several structures (`--accel kd,bvh`, the default) each round runs
Embree, then Sahara's kd-tree, then its hierarchy, so every ratio is taken
at the same moment; the tables put the structures side by side.
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


def same_rays_check(exe, mesh, accel, builder, bvh_builder):
    """Secondary sets start at each tracer's own primary hits, so a few ulps
    of difference in a primary t move them. Trace Sahara's shadow and
    diffuse sets from Embree's primary hits instead: bit-identical rays."""
    hits = os.path.join(ROOT, "target", "embree", "primary.hits")
    subprocess.run([exe, mesh, "--runs", "1", "--no-build-times", "--sets", "primary",
                    "--dump", "primary", hits], check=True, capture_output=True)
    out = subprocess.run([SAHARA, "bench", mesh, "--json", "--runs", "1", "--accel", accel,
                          "--builder", builder, "--bvh-builder", bvh_builder,
                          "--sets", "shadow,diffuse", "--primary-hits", hits],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)["sets"]


def run_sahara(mesh, runs, accel, builder, bvh_builder):
    out = subprocess.run([SAHARA, "bench", mesh, "--json", "--runs", str(runs), "--accel", accel,
                          "--builder", builder, "--bvh-builder", bvh_builder],
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


def ratio(a, b):
    return f"{a:.2f} ({a / b:.2f})" if b else f"{a:.2f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--accel", default="kd,bvh", help="structures, in the order run: kd, bvh")
    ap.add_argument("--builder", default="sah", help="the kd-tree's builder")
    ap.add_argument("--bvh-builder", default="spatial", help="the hierarchy's builder")
    ap.add_argument("--meshes", default=",".join(MESHES))
    ap.add_argument("--no-embree", action="store_true")
    a = ap.parse_args()
    accels = a.accel.split(",")
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
        s_best = {k: None for k in accels}
        e_best = None
        for _ in range(a.rounds):
            if exe:
                e_best = best(e_best, run_embree(exe, path, a.runs))
            for k in accels:
                s_best[k] = best(s_best[k], run_sahara(path, a.runs, k, a.builder, a.bvh_builder))
        if e_best:
            for k in accels:
                s_best[k]["same_rays"] = same_rays_check(exe, path, k, a.builder, a.bvh_builder)
        rows.append((os.path.basename(os.path.dirname(path)), s_best, e_best))
        print(f"done {m}", file=sys.stderr)
    names = {k: ("kd-tree" if k == "kd" else "BVH") for k in accels}
    print(f"Load average at start: {' '.join(load)}; {a.rounds} rounds x best of {a.runs} runs; "
          f"kd-tree builder `{a.builder}`, BVH builder `{a.bvh_builder}`.\n")
    print("Mrays/s on one thread by the tracing thread's CPU time, with the ratio to Embree's "
          "single rays of the same set in brackets; batch: one batch call over the set; "
          "2T: wall clock on two threads, against Embree's on two.\n")
    head = " | ".join(f"{names[k]} 1T | {names[k]} batch 1T | {names[k]} 2T" for k in accels)
    print(f"| mesh | set | rays | hits (agree) | Embree 1T | Embree 2T | {head} |")
    print("|---|---|---|---|---|---|" + "---|" * (3 * len(accels)))
    for name, ss, e in rows:
        for st in SETS:
            ev = e["sets"].get(st) if e else None
            first = ss[accels[0]]["sets"][st]
            ok = all(agree(ss[k]["sets"][st], ev) or
                     (ss[k].get("same_rays") or {}).get(st) is not None and agree(ss[k]["same_rays"][st], ev)
                     for k in accels) if ev else None
            cells = []
            for k in accels:
                sv = ss[k]["sets"][st]
                b = ev["mrays_1t_cpu"] if ev else 0
                b2 = ev["mrays_all"] if ev else 0
                cells += [ratio(sv["mrays_1t_cpu"], b), ratio(sv.get("mrays_batch_1t_cpu", 0), b),
                          ratio(sv["mrays_all"], b2)]
            agree_cell = "-" if ok is None else ("yes" if ok else "**no**")
            e1 = f"{ev['mrays_1t_cpu']:.2f}" if ev else "-"
            e2 = f"{ev['mrays_all']:.2f}" if ev else "-"
            print(f"| {name} | {st} | {first['rays']:,} | {first['hits']:,} ({agree_cell}) | {e1} | {e2} | "
                  + " | ".join(cells) + " |")
        for sk, slabel, ek in (("mrays_packet_1t_cpu", "8 (4x2)", "prim_p8"),
                               ("mrays_packet16_1t_cpu", "16 (4x4)", "prim_p16")):
            if not (e and ek in e["sets"]):
                continue
            ev = e["sets"][ek]["mrays_1t_cpu"]
            cells = []
            for k in accels:
                p = ss[k]["sets"]["primary"].get(sk)
                cells += [ratio(p, ev) if p is not None else "-", "", ""]
            print(f"| {name} | primary in packets of {slabel} | | | {ev:.2f} | | " + " | ".join(cells) + " |")
    print("\n| mesh | triangles | Embree HIGH / MEDIUM build ms | Embree BVH MB (+ buffers) | "
          + " | ".join(f"{names[k]} build ms | {names[k]} MB" for k in accels) + " |")
    print("|---|---|---|---|" + "---|" * (2 * len(accels)))
    for name, ss, e in rows:
        eb = f"{e['build_ms']:.1f} / {e.get('build_medium_ms', float('nan')):.1f}" if e else "-"
        em = f"{e['memory_bytes'] / 1e6:.1f} (+{e.get('buffer_bytes', 0) / 1e6:.1f})" if e else "-"
        first = ss[accels[0]]
        print(f"| {name} | {first['triangles']:,} | {eb} | {em} | "
              + " | ".join(f"{ss[k]['build_ms']:.1f} | {ss[k]['memory_bytes'] / 1e6:.1f}" for k in accels) + " |")


if __name__ == "__main__":
    main()
