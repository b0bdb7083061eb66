#!/usr/bin/env python3
"""Every builder on every shared mesh: build time, tree statistics, SAH cost
and Mrays/s of the four protocol ray sets (1 thread), as a markdown table.

Usage: scripts/builders_table.py [--runs N] [--meshes a,b] [--builders a,b]
Run from the repository root after `cargo build --release`.
"""
import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.environ.get("SAHARA_SCENES", os.path.join(ROOT, "..", "shared", "scenes"))
SAHARA = os.path.join(ROOT, "target", "release", "sahara")
MESHES = ["bunny/bunny.obj", "dragon/dragon.obj", "sponza/sponza.obj",
          "teapot_stadium/teapot_stadium.obj", "cornell_box/cornell_box.obj"]
BUILDERS = ["sah", "binned", "rr-middle", "rr-median", "largest-middle", "largest-median"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--meshes", default=",".join(MESHES))
    ap.add_argument("--builders", default=",".join(BUILDERS))
    a = ap.parse_args()
    print(f"Load average at start: {' '.join(open('/proc/loadavg').read().split()[:3])}; best of {a.runs} runs.\n")
    print("Mrays/s on 1 thread, by the tracing thread's CPU time (`mrays_1t_cpu`).\n")
    print("| mesh | builder | build ms | nodes | depth | refs/tri | MB | SAH cost | "
          "primary | shadow | diffuse | random |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for m in a.meshes.split(","):
        path = os.path.join(SCENES, m)
        for b in a.builders.split(","):
            st = json.loads(subprocess.run([SAHARA, "stats", path, "--json", "--builder", b],
                                           check=True, capture_output=True, text=True).stdout)
            r = json.loads(subprocess.run([SAHARA, "bench", path, "--json", "--runs", str(a.runs),
                                           "--builder", b], check=True, capture_output=True,
                                          text=True).stdout)
            t = st
            s = r["sets"]
            print(f"| {os.path.basename(os.path.dirname(path))} | {b} | {r['build_ms']:.0f} | "
                  f"{t['nodes']:,} | {t['max_depth']} | {t['duplication']:.2f} | "
                  f"{r['memory_bytes'] / 1e6:.1f} | {r['sah_cost']:.1f} | "
                  + " | ".join(f"{s[k]['mrays_1t_cpu']:.2f}" for k in ("primary", "shadow", "diffuse", "random"))
                  + " |", flush=True)
        print(f"done {m}", file=sys.stderr)


if __name__ == "__main__":
    main()
