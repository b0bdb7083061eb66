#!/usr/bin/env python3
"""Writes the glTF scenes of the automatic camera's end-to-end tests
(crates/sahara/tests/end_to_end/render.rs), each a small .gltf with its buffer inline:

- island_sea.gltf: a palm of sorts (a trunk and four flat leaves, about 6
  units tall) on an island of sand 20 units across, in a sea 392 units
  wide whose waves rise and fall by 2 units and whose emissive factor is
  [1, 1, 1] (glowing white, as exporters often leave it); ten nodes in all.
- open_room.gltf: a Cornell box (five one-sided walls, open at +z, 556 x
  548 x 559), a block and a small light under the ceiling.

Run from this folder: python3 make_framing_scenes.py
"""

import base64
import json
import math
import struct


class Gltf:
    def __init__(self):
        self.bin = bytearray()
        self.doc = {
            "asset": {"version": "2.0", "generator": "make_framing_scenes.py"},
            "buffers": [],
            "bufferViews": [],
            "accessors": [],
            "materials": [],
            "meshes": [],
            "nodes": [],
            "scenes": [{"nodes": []}],
            "scene": 0,
        }

    def material(self, name, colour, emissive=None, double_sided=False):
        m = {
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": list(colour) + [1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 0.8,
            },
            "doubleSided": double_sided,
        }
        if emissive:
            m["emissiveFactor"] = list(emissive)
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def _view(self, data, target):
        while len(self.bin) % 4:
            self.bin.append(0)
        off = len(self.bin)
        self.bin += data
        self.doc["bufferViews"].append(
            {"buffer": 0, "byteOffset": off, "byteLength": len(data), "target": target}
        )
        return len(self.doc["bufferViews"]) - 1

    def mesh(self, name, positions, triangles, material, translation=(0, 0, 0)):
        pos = b"".join(struct.pack("<3f", *p) for p in positions)
        idx = b"".join(struct.pack("<3I", *t) for t in triangles)
        pv = self._view(pos, 34962)
        iv = self._view(idx, 34963)
        acc = self.doc["accessors"]
        acc.append(
            {
                "bufferView": pv,
                "componentType": 5126,
                "count": len(positions),
                "type": "VEC3",
                "min": [min(p[k] for p in positions) for k in range(3)],
                "max": [max(p[k] for p in positions) for k in range(3)],
            }
        )
        acc.append(
            {"bufferView": iv, "componentType": 5125, "count": 3 * len(triangles), "type": "SCALAR"}
        )
        self.doc["meshes"].append(
            {
                "name": name,
                "primitives": [
                    {"attributes": {"POSITION": len(acc) - 2}, "indices": len(acc) - 1, "material": material}
                ],
            }
        )
        self.doc["nodes"].append(
            {"name": name, "mesh": len(self.doc["meshes"]) - 1, "translation": list(translation)}
        )
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def write(self, path):
        self.doc["buffers"] = [
            {
                "byteLength": len(self.bin),
                "uri": "data:application/octet-stream;base64,"
                + base64.b64encode(bytes(self.bin)).decode(),
            }
        ]
        with open(path, "w") as f:
            json.dump(self.doc, f, indent=1)
            f.write("\n")


def box(lo, hi):
    """A closed box: 8 corners, 12 triangles facing out."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    p = [(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    t = []
    for a, b, c, d in quads:
        t += [(a, b, c), (a, c, d)]
    return p, t


def quad(corner, u, v):
    """A one-sided quad, facing along u x v."""
    c = corner
    p = [c, tuple(c[k] + u[k] for k in range(3)), tuple(c[k] + u[k] + v[k] for k in range(3)),
         tuple(c[k] + v[k] for k in range(3))]
    return p, [(0, 1, 2), (0, 2, 3)]


def island_sea(path):
    g = Gltf()
    sand = g.material("Sand", (0.8, 0.7, 0.45))
    bark = g.material("Bark", (0.35, 0.22, 0.1))
    leaf = g.material("Leaf", (0.15, 0.55, 0.1), double_sided=True)
    water = g.material("Water", (0.1, 0.35, 0.5), emissive=(1.0, 1.0, 1.0))
    g.mesh("Island", *box((-10, -1, -10), (10, 0.5, 10)), sand)
    g.mesh("Trunk", *box((-0.3, 0.5, -0.3), (0.3, 6, 0.3)), bark)
    for k, (dx, dz) in enumerate([(1, 0), (0, 1), (-1, 0), (0, -1)]):
        side = (-dz * 0.5, 0, dx * 0.5)
        g.mesh(f"Leaf{k}", *quad((-side[0] / 1, 6, -side[2] / 1), (3 * dx, -1, 3 * dz), (2 * side[0], 0, 2 * side[2])), leaf)
    # Rocks and a coconut: small things beside the palm.
    g.mesh("Rock0", *box((3, 0.5, 2), (4, 1.2, 3)), sand)
    g.mesh("Rock1", *box((-5, 0.5, -3), (-4.2, 1.0, -2.2)), sand)
    g.mesh("Coconut", *box((0.4, 0.5, 0.4), (0.8, 0.9, 0.8)), bark)
    n, side = 24, 392.0
    pos, tri = [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x, z = i / n - 0.5, j / n - 0.5
            pos.append((side * x, -0.5 + (math.sin(7 * x) + math.cos(5 * z)), side * z))
    for j in range(n):
        for i in range(n):
            k = j * (n + 1) + i
            tri += [(k, k + n + 1, k + 1), (k + 1, k + n + 1, k + n + 2)]
    g.mesh("Sea", pos, tri, water)
    g.write(path)


def open_room(path):
    g = Gltf()
    white = g.material("White", (0.73, 0.73, 0.73))
    red = g.material("Red", (0.63, 0.065, 0.05))
    green = g.material("Green", (0.14, 0.45, 0.09))
    light = g.material("Light", (0.78, 0.78, 0.78), emissive=(1.0, 1.0, 1.0))
    s, h, d = 556.0, 548.0, 559.0
    o = (-s, 0.0, 0.0)
    X, Y, Z = (s, 0, 0), (0, h, 0), (0, 0, d)
    add = lambda a, b: tuple(a[k] + b[k] for k in range(3))
    # Each wall faces into the room (one-sided: from outside it is culled).
    g.mesh("Floor", *quad(o, Z, X), white)
    g.mesh("Ceiling", *quad(add(o, Y), X, Z), white)
    g.mesh("Back", *quad(o, X, Y), white)
    g.mesh("Left", *quad(o, Y, Z), red)
    g.mesh("Right", *quad(add(o, X), Z, Y), green)
    g.mesh("Block", *box((-400, 0, 100), (-250, 330, 250)), white)
    g.mesh("Light", *quad((-343, h - 1, 227), (130, 0, 0), (0, 0, 105)), light)
    g.write(path)


if __name__ == "__main__":
    island_sea("island_sea.gltf")
    open_room("open_room.gltf")
