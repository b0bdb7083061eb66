#!/usr/bin/env python3
"""Writes scenes/kit/hall_lamps.xml: a hall lit by 120 small sphere lamps of differing power, in
Mitsuba 3's format (Sahara and Mitsuba 3 both read it). The lamps are placed and coloured by a fixed
pseudo-random sequence, so the file is the same every time.

The hall is 24 x 5 x 12 (x, y, z), its floor at y = 0; two rows of square pillars; a few boxes on
the floor. The lamps hang in three rows along the hall and stand in a row along each side wall:
their radiance spans about two orders of magnitude, so a light choice that ignores where the
shading point is wastes most of its samples on lamps that are far away or dim.

usage: python3 scripts/kit_hall_lamps.py [OUT]   (default scenes/kit/hall_lamps.xml)
"""
import os
import sys

import kit_xml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rng(seed):
    """xorshift64: a fixed sequence of floats in [0, 1)."""
    s = seed
    while True:
        s ^= (s << 13) & 0xFFFFFFFFFFFFFFFF
        s ^= s >> 7
        s ^= (s << 17) & 0xFFFFFFFFFFFFFFFF
        yield (s >> 11) / float(1 << 53)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "scenes", "kit", "hall_lamps.xml")
    r = rng(0x9E3779B97F4A7C15)
    nxt = lambda: next(r)
    lines = []
    add = lines.append
    add('<!-- A hall lit by 120 small sphere lamps of differing power (written by')
    add('     scripts/kit_hall_lamps.py). Parameters: spp, width, height, max_depth.')
    add('     Render: sahara render scenes/kit/hall_lamps.xml -D spp=64')
    add('     Mitsuba 3: mitsuba -D spp=64 scenes/kit/hall_lamps.xml -->')
    kit_xml.scene_start(add, width=320, height=180, max_depth=6, fov=60,
                        origin="-11.5, 1.8, 1.2", target="6, 1.5, -0.6")
    kit_xml.diffuse(add, [("wall", "0.7, 0.68, 0.64"), ("floor", "0.45, 0.42, 0.4"),
                          ("pillar", "0.6, 0.6, 0.62"), ("red", "0.6, 0.12, 0.1"),
                          ("blue", "0.12, 0.2, 0.55"), ("black", "0, 0, 0")])
    add('')

    def box(cx, cy, cz, sx, sy, sz, mat):
        add('    <shape type="cube">')
        add('        <transform name="to_world">')
        add(f'            <scale x="{sx / 2:g}" y="{sy / 2:g}" z="{sz / 2:g}"/>')
        add(f'            <translate x="{cx:g}" y="{cy:g}" z="{cz:g}"/>')
        add('        </transform>')
        add(f'        <ref id="{mat}"/>')
        add('    </shape>')

    def rect(matrix, mat):
        kit_xml.rect(add, matrix, mat)

    add('    <!-- floor, ceiling, walls: rectangles scaled from [-1, 1]^2 -->')
    rect("12 0 0 0  0 0 1 0  0 -6 0 0  0 0 0 1", "floor")
    rect("12 0 0 0  0 0 -1 5  0 6 0 0  0 0 0 1", "wall")
    rect("12 0 0 0  0 2.5 0 2.5  0 0 1 -6  0 0 0 1", "wall")
    rect("-12 0 0 0  0 2.5 0 2.5  0 0 -1 6  0 0 0 1", "wall")
    rect("0 0 1 -12  0 2.5 0 2.5  -6 0 0 0  0 0 0 1", "wall")
    rect("0 0 -1 12  0 2.5 0 2.5  6 0 0 0  0 0 0 1", "wall")
    add('    <!-- pillars and boxes -->')
    for i in range(6):
        x = -9 + 3.6 * i
        for z in (-3.0, 3.0):
            box(x, 2.5, z, 0.5, 5.0, 0.5, "pillar")
    box(-4.0, 0.4, 0.5, 0.8, 0.8, 0.8, "red")
    box(1.5, 0.6, -1.2, 1.2, 1.2, 0.6, "blue")
    box(6.0, 0.3, 1.0, 2.0, 0.6, 0.6, "pillar")
    add('    <!-- lamps: three rows hanging along the hall, one row along each side wall -->')
    lamps = []
    for row, z in enumerate((-4.5, 0.0, 4.5)):
        for i in range(28):
            lamps.append((-11.2 + 0.83 * i, 3.6 + 0.5 * nxt(), z + 0.6 * (nxt() - 0.5)))
    for z in (-5.8, 5.8):
        for i in range(18):
            lamps.append((-10.8 + 1.27 * i, 1.2 + 0.6 * nxt(), z))
    assert len(lamps) == 120
    for (x, y, z) in lamps:
        power = 10 ** (2.0 * nxt())  # 1 .. 100
        warm = nxt()
        rgb = (power * (1.0 + 0.3 * warm), power, power * (1.0 - 0.4 * warm))
        radius = 0.05 + 0.04 * nxt()
        add('    <shape type="sphere">')
        add(f'        <point name="center" x="{x:.4f}" y="{y:.4f}" z="{z:.4f}"/>')
        add(f'        <float name="radius" value="{radius:.4f}"/>')
        add('        <ref id="black"/>')
        add('        <emitter type="area">')
        add(f'            <rgb name="radiance" value="{rgb[0]:.4f}, {rgb[1]:.4f}, {rgb[2]:.4f}"/>')
        add('        </emitter>')
        add('    </shape>')
    add('</scene>')
    kit_xml.write(out, lines)


if __name__ == "__main__":
    main()
