#!/usr/bin/env python3
"""Writes scenes/kit/door_ajar.xml: a room lit only through a door ajar from a lit room beside it,
in Mitsuba 3's format (Sahara and Mitsuba 3 both read it).

Room A (x 0..6, z 0..5, 3 high), where the camera stands, and room B (x 6..10) share a wall at
x = 6 with a doorway (z 2..3, 2.2 high). The door, hinged at z = 2 on room B's side, stands open by
20 degrees: light reaches room A only through the wedge between its free edge and the jamb. The one
light is a panel on room B's ceiling beside the shared wall, which the camera cannot see through the
doorway: every light path into room A scatters in room B first, and a path traced from the camera
finds the gap only by chance -- the case path guiding is for.

usage: python3 scripts/kit_door_ajar.py [OUT]   (default scenes/kit/door_ajar.xml)
"""
import os
import sys

import kit_xml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "scenes", "kit", "door_ajar.xml")
    lines = []
    add = lines.append
    add('<!-- A room lit only through a door ajar from a lit room beside it (written by')
    add('     scripts/kit_door_ajar.py). Parameters: spp, width, height, max_depth.')
    add('     Render: sahara render scenes/kit/door_ajar.xml -D spp=64')
    add('     Mitsuba 3: mitsuba -D spp=64 scenes/kit/door_ajar.xml -->')
    kit_xml.scene_start(add, width=240, height=135, max_depth=10, fov=65,
                        origin="0.6, 1.6, 4.5", target="6, 1.0, 2.0")
    kit_xml.diffuse(add, [("wall", "0.75, 0.73, 0.7"), ("floor", "0.5, 0.4, 0.3"),
                          ("door", "0.55, 0.35, 0.2"), ("green", "0.2, 0.5, 0.25"),
                          ("black", "0, 0, 0")])
    add('')

    def box(x0, x1, y0, y1, z0, z1, mat, rot_y=None):
        """An axis-aligned box [x0, x1] x [y0, y1] x [z0, z1], turned by rot_y = (degrees, hinge
        x, hinge z) about a vertical axis if given."""
        add('    <shape type="cube">')
        add('        <transform name="to_world">')
        add(f'            <scale x="{(x1 - x0) / 2:g}" y="{(y1 - y0) / 2:g}" z="{(z1 - z0) / 2:g}"/>')
        add(f'            <translate x="{(x0 + x1) / 2:g}" y="{(y0 + y1) / 2:g}" z="{(z0 + z1) / 2:g}"/>')
        if rot_y:
            deg, hx, hz = rot_y
            add(f'            <translate x="{-hx:g}" z="{-hz:g}"/>')
            add(f'            <rotate y="1" angle="{deg:g}"/>')
            add(f'            <translate x="{hx:g}" z="{hz:g}"/>')
        add('        </transform>')
        add(f'        <ref id="{mat}"/>')
        add('    </shape>')

    def rect(matrix, mat, radiance=None):
        kit_xml.rect(add, matrix, mat, radiance)

    add('    <!-- floor and ceiling of both rooms: rectangles scaled from [-1, 1]^2 -->')
    rect("5 0 0 5  0 0 1 0  0 -2.5 0 2.5  0 0 0 1", "floor")
    rect("5 0 0 5  0 0 -1 3  0 2.5 0 2.5  0 0 0 1", "wall")
    add('    <!-- outer walls -->')
    rect("0 0 1 0  0 1.5 0 1.5  -2.5 0 0 2.5  0 0 0 1", "wall")       # x = 0
    rect("0 0 -1 10  0 1.5 0 1.5  2.5 0 0 2.5  0 0 0 1", "wall")      # x = 10
    rect("5 0 0 5  0 1.5 0 1.5  0 0 1 0  0 0 0 1", "wall")            # z = 0
    rect("-5 0 0 5  0 1.5 0 1.5  0 0 -1 5  0 0 0 1", "wall")          # z = 5
    add('    <!-- the shared wall at x = 6, with a doorway z 2..3, 2.2 high -->')
    box(5.95, 6.05, 0, 3, 0, 2, "wall")
    box(5.95, 6.05, 0, 3, 3, 5, "wall")
    box(5.95, 6.05, 2.2, 3, 2, 3, "wall")
    add('    <!-- the door, hinged at z = 2 on room B\'s side, open by 20 degrees -->')
    box(6.05, 6.1, 0.0, 2.18, 2.0, 2.98, "door", rot_y=(20, 6.05, 2.0))
    add('    <!-- furniture in room A -->')
    box(2.0, 3.2, 0, 0.8, 0.6, 1.6, "green")
    box(0.3, 0.9, 0, 1.8, 1.5, 3.5, "door")
    add('    <!-- the light: a panel on room B\'s ceiling beside the shared wall -->')
    rect("0.5 0 0 6.8  0 0 -1 2.99  0 0.5 0 0.8  0 0 0 1", "black", "2000, 1800, 1500")
    add('</scene>')
    kit_xml.write(out, lines)


if __name__ == "__main__":
    main()
