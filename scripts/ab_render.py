#!/usr/bin/env python3
"""A/B speed comparison of Sahara builds on renders, interleaved.

Each configuration is a `sahara` binary; every round renders every scene
with every configuration back to back (`sahara render SCENE ARGS --threads
1`), and the table gives each configuration's best CPU seconds per sample
per pixel of the passes (the `CPU s` of the closing line, which leaves out
loading and tree builds) and its ratio to the first configuration (> 1:
faster). The images are compared too: two builds meant to give the same
image must write the same EXR bytes, and the table says whether they did.

Usage:
  scripts/ab_render.py [--rounds 3] [--spp 16] [--size 256] CONFIG [CONFIG ...]
  scripts/ab_render.py /tmp/sahara-before target/release/sahara
Scenes: the built-in Cornell box (path and distribution) and the example
scenes in scenes/; add any with --scene "NAME=PATH [render args]".
"""
import argparse
import filecmp
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = [
    ("cornell path", ""),
    ("cornell distribution", "--integrator distribution"),
    ("cornell_glossy_glass", os.path.join(ROOT, "scenes", "cornell_glossy_glass.toml")),
    ("bunny_dof", os.path.join(ROOT, "scenes", "bunny_dof.toml")),
    ("motion_blur", os.path.join(ROOT, "scenes", "motion_blur.toml")),
]


def render(binary, scene_args, spp, size, out):
    cmd = [binary, "render"] + scene_args.split() + [
        "--spp", str(spp), "--width", str(size), "--height", str(size), "--threads", "1",
        "-o", out]
    p = subprocess.run(cmd, capture_output=True, text=True)
    m = re.search(r"([0-9.]+) CPU s", p.stderr)
    if p.returncode != 0 or not m:
        sys.exit(f"{' '.join(cmd)} failed:\n{p.stderr}")
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--scene", action="append", default=[],
                    help='"NAME=PATH [render args]", added to the built-in list')
    ap.add_argument("--only", action="store_true", help="render only the --scene scenes")
    ap.add_argument("configs", nargs="+")
    args = ap.parse_args()
    scenes = [] if args.only else list(SCENES)
    for s in args.scene:
        name, _, rest = s.partition("=")
        scenes.append((name, rest))
    best = {}
    same = {}
    with tempfile.TemporaryDirectory() as tmp:
        for rnd in range(args.rounds):
            for si, (name, scene) in enumerate(scenes):
                for ci, c in enumerate(args.configs):
                    out = os.path.join(tmp, f"{si}-{ci}.exr")
                    t = render(c, scene, args.spp, args.size, out)
                    best[(si, ci)] = min(best.get((si, ci), float("inf")), t)
                    if ci > 0:
                        same[(si, ci)] = filecmp.cmp(out, os.path.join(tmp, f"{si}-0.exr"),
                                                     shallow=False)
            print(f"round {rnd + 1} of {args.rounds} done", file=sys.stderr)
    print(f"{args.size}x{args.size}, {args.spp} spp, 1 thread; CPU ms per spp, best of "
          f"{args.rounds} interleaved rounds; ratio to the first (> 1: faster); same image bytes\n")
    head = "| scene | " + " | ".join(f"`{c}`" for c in args.configs) + " |"
    print(head)
    print("|---|" + "---|" * len(args.configs))
    for si, (name, _) in enumerate(scenes):
        cells = []
        for ci in range(len(args.configs)):
            ms = 1e3 * best[(si, ci)] / args.spp
            if ci == 0:
                cells.append(f"{ms:.1f}")
            else:
                r = best[(si, 0)] / best[(si, ci)]
                cells.append(f"{ms:.1f} ({r:.2f}x, {'same' if same[(si, ci)] else '**differs**'})")
        print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
