#!/usr/bin/env python3
"""Writes a pbrt-v4 scene of N x N instances of the Stanford dragon.

    python3 scripts/pbrt_dragon_field.py [--side 100] [--out /tmp/dragons.pbrt]

The dragon is read from $SAHARA_SCENES/dragon/dragon.ply (871,414
triangles) as one pbrt object; each instance places it on a grid with its
own rotation, scale and material colour, so 100 x 100 instances hold about
8.7e9 triangles. The file stays small (one line per instance): the scene is
generated, never committed. See docs/pbrt.md for the build and render times.
"""

import argparse
import math
import os
import random
from pathlib import Path


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--side", type=int, default=100, help="instances per row (N x N in all)")
    ap.add_argument("--out", type=Path, default=Path("/tmp/dragons.pbrt"))
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    scenes = Path(os.environ.get("SAHARA_SCENES", Path(__file__).resolve().parents[2] / "shared" / "scenes"))
    ply = scenes / "dragon" / "dragon.ply"
    if not ply.is_file():
        raise SystemExit(f"{ply}: not found (set SAHARA_SCENES)")
    n = args.side
    rng = random.Random(args.seed)
    # The dragon is about 0.2 units long; instances stand 0.25 apart.
    step = 0.25
    half = 0.5 * step * (n - 1)
    lines = [
        f"# {n} x {n} instances of the Stanford dragon ({n * n * 871414:.3g} triangles instanced)",
        f"LookAt {-0.15 * half - 0.5} {0.5 + 0.25 * half} {-0.15 * half - 0.5}  {0.35 * half} 0.05 {0.35 * half}  0 1 0",
        'Camera "perspective" "float fov" 40',
        'Film "rgb" "integer xresolution" 640 "integer yresolution" 360 "string filename" "dragons.png"',
        'Sampler "zsobol" "integer pixelsamples" 16',
        'Integrator "path" "integer maxdepth" 4',
        "WorldBegin",
        'LightSource "infinite" "rgb L" [0.4 0.45 0.5]',
        'LightSource "distant" "point3 from" [1 3 2] "point3 to" [0 0 0] "rgb L" [2.5 2.4 2.2]',
        'AttributeBegin',
        '  Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]',
        f'  Shape "trianglemesh" "point3 P" [{-half - 1} 0.053 {-half - 1}  {half + 1} 0.053 {-half - 1}  {half + 1} 0.053 {half + 1}  {-half - 1} 0.053 {half + 1}] "integer indices" [0 2 1 0 3 2]',
        'AttributeEnd',
        'ObjectBegin "dragon"',
        '  Material "coateddiffuse" "rgb reflectance" [0.6 0.25 0.1] "float roughness" 0.05',
        f'  Shape "plymesh" "string filename" "{ply}"',
        "ObjectEnd",
    ]
    for i in range(n):
        for j in range(n):
            x = -half + i * step + rng.uniform(-0.03, 0.03)
            z = -half + j * step + rng.uniform(-0.03, 0.03)
            s = rng.uniform(0.8, 1.2)
            a = rng.uniform(0, 360)
            lines.append(
                f'AttributeBegin Translate {x:.4f} {0.053 * (1 - s):.4f} {z:.4f} Rotate {a:.1f} 0 1 0 Scale {s:.3f} {s:.3f} {s:.3f} ObjectInstance "dragon" AttributeEnd'
            )
    args.out.write_text("\n".join(lines) + "\n")
    print(f"{args.out}: {n * n} instances, {n * n * 871414:.3g} triangles instanced")


if __name__ == "__main__":
    main()
