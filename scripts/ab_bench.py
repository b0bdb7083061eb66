#!/usr/bin/env python3
"""A/B speed comparison of Sahara builds (or options), interleaved.

Each configuration is a `sahara` binary with optional extra `bench`
arguments, e.g. a copy of the release binary built before a change and the
one built after it, or one binary with and without `--compact-leaves`.
Every round runs every mesh under every configuration back to back
(`sahara bench MESH --json --threads 1 --runs R --sets S`), so that the
configurations share the machine's moments; the table gives, per mesh and
set, each configuration's best Mrays/s over the rounds (one thread, by the
tracing thread's CPU time; `primary_pk` and `primary_pk16` are the 8- and
16-ray packet paths, `SET_batch` one batch call over the set) and its
ratio to the first configuration.

Best of several rounds rather than the median: on the shared virtual
machines this project is measured on, a process's figures sometimes all
come out 20-30% low for a while; the best of each configuration is the
figure least touched by that. A configuration that looks faster in every
set by the same factor is worth one more run in another order.

Usage:
  scripts/ab_bench.py [--meshes bunny,dragon] [--sets primary,random]
                      [--rounds 3] [--runs 2] CONFIG [CONFIG ...]
  CONFIG = "PATH/TO/sahara [bench args]", e.g.
  scripts/ab_bench.py /tmp/sahara-before target/release/sahara
  scripts/ab_bench.py "target/release/sahara" \
                      "target/release/sahara --compact-leaves"
The meshes are read from $SAHARA_SCENES or ../shared/scenes (NAME means
NAME/NAME.obj there).
"""
import argparse
import json
import os
import shlex
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.environ.get("SAHARA_SCENES", os.path.join(ROOT, "..", "shared", "scenes"))


def bench(config, mesh, sets, runs):
    """One `sahara bench --json` run: {set: Mrays/s}, with `SET_pk` for packets."""
    parts = shlex.split(config)
    path = os.path.join(SCENES, mesh, mesh + ".obj")
    cmd = parts[:1] + ["bench", path, "--json", "--threads", "1",
                       "--runs", str(runs), "--sets", sets] + parts[1:]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{done.stderr.strip()}")
    figures = {}
    for name, s in json.loads(done.stdout)["sets"].items():
        figures[name] = s["mrays_1t_cpu"]
        if "mrays_batch_1t_cpu" in s:
            figures[name + "_batch"] = s["mrays_batch_1t_cpu"]
        if "mrays_packet_1t_cpu" in s:
            figures[name + "_pk"] = s["mrays_packet_1t_cpu"]
        if "mrays_packet16_1t_cpu" in s:
            figures[name + "_pk16"] = s["mrays_packet16_1t_cpu"]
    return figures


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--meshes", default="bunny,dragon,sponza,teapot_stadium")
    ap.add_argument("--sets", default="primary,shadow,diffuse,random")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("configs", nargs="+", metavar="CONFIG")
    a = ap.parse_args()
    best = {}
    meshes = a.meshes.split(",")
    for r in range(a.rounds):
        for mesh in meshes:
            for c in a.configs:
                for name, v in bench(c, mesh, a.sets, a.runs).items():
                    key = (mesh, name, c)
                    best[key] = max(best.get(key, 0.0), v)
        print(f"round {r + 1} of {a.rounds} done", file=sys.stderr)
    rows = sorted({(m, s) for (m, s, _) in best}, key=lambda k: (meshes.index(k[0]), k[1]))
    print("| mesh | set | " + " | ".join(f"`{c}`" for c in a.configs) + " |")
    print("|---|---|" + "---|" * len(a.configs))
    for mesh, name in rows:
        # A figure only some configurations report (e.g. a packet path an
        # older binary lacks) is shown without a ratio where the first lacks it.
        base = best.get((mesh, name, a.configs[0]))
        cells = []
        for c in a.configs:
            v = best.get((mesh, name, c))
            cells.append("-" if v is None else f"{v:.3f}" + (f" ({v / base:.3f})" if base else ""))
        print(f"| {mesh} | {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
