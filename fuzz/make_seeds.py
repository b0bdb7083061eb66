#!/usr/bin/env python3
"""Builds the fuzz seed corpora in fuzz/corpus/<target>/ at run time.

Seeds are small files made from the benchmark meshes ($SAHARA_SCENES, else
../shared/scenes beside the repository; the Cornell box and the bunny PLY
fall back to the copies in scenes/assets): the Cornell box whole, the first lines of
the big OBJ files, PLY files cut down to their first vertices and the faces
among them (in every encoding), a tiny glTF and GLB, tiny PNG/HDR images and a
small JPEG texture; plus the hand-made seeds in fuzz/seeds/<target>/. Nothing
here is committed: the corpus folder is rebuilt (seeds are only added; inputs
libFuzzer found before are kept). Missing scene files are skipped.
"""

import base64
import json
import os
import struct
import sys
import zlib
from pathlib import Path

FUZZ = Path(__file__).resolve().parent
REPO = FUZZ.parent
SCENES = Path(os.environ.get("SAHARA_SCENES") or REPO.parent / "shared" / "scenes")
ASSETS = REPO / "scenes" / "assets"
CORPUS = FUZZ / "corpus"


def put(target, name, data):
    folder = CORPUS / target
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"seed-{name}").write_bytes(data if isinstance(data, bytes) else data.encode())


def read(rel, limit=None):
    path = SCENES / rel
    if not path.is_file() and (ASSETS / Path(rel).name).is_file():
        path = ASSETS / Path(rel).name
    if not path.is_file():
        print(f"make_seeds: {SCENES / rel} missing, skipped", file=sys.stderr)
        return None
    with open(path, "rb") as f:
        return f.read(limit) if limit else f.read()


def first_lines(data, size):
    """The whole lines within the first `size` bytes."""
    cut = data[:size]
    return cut[: cut.rfind(b"\n") + 1] if b"\n" in cut else cut


def obj_seeds():
    for rel in ["cornell_box/cornell_box.obj"]:
        data = read(rel)
        if data:
            put("obj", Path(rel).name, data)
    for rel in ["bunny/bunny.obj", "teapot_stadium/teapot_stadium.obj", "sponza/sponza.obj"]:
        data = read(rel, 64 * 1024)
        if not data:
            continue
        lines = first_lines(data, 64 * 1024).splitlines(keepends=True)
        # Keep the vertices up to 2 KB, then faces that only use them.
        out, vertices = [], 0
        for line in lines:
            words = line.split()
            if words[:1] == [b"v"]:
                if sum(map(len, out)) < 2048:
                    out.append(line)
                    vertices += 1
            elif words[:1] == [b"f"]:
                ok = all(
                    0 < int(w.split(b"/")[0]) <= vertices
                    for w in words[1:]
                    if w.split(b"/")[0].lstrip(b"-").isdigit()
                )
                if ok and sum(map(len, out)) < 4096:
                    out.append(line)
            elif sum(map(len, out)) < 4096:
                out.append(line)
        put("obj", Path(rel).stem + "-head.obj", b"".join(out))




def ply_small(data, keep_vertices=48):
    """A binary little-endian x,y,z + uchar/int-list PLY cut to its first
    vertices and the faces among them: (vertices, faces)."""
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    if "binary_little_endian" not in header or "list uchar int" not in header:
        return None
    vertex_count = int(header.split("element vertex ")[1].split()[0])
    pos = end
    vertices = [struct.unpack_from("<3f", data, pos + 12 * i) for i in range(min(keep_vertices, vertex_count))]
    pos += 12 * vertex_count
    faces = []
    while pos < len(data) and len(faces) < 64:
        n = data[pos]
        face = struct.unpack_from(f"<{n}i", data, pos + 1)
        pos += 1 + 4 * n
        if all(i < len(vertices) for i in face):
            faces.append(face)
    return vertices, faces


def ply_write(vertices, faces, encoding, extra=False):
    head = ["ply", f"format {encoding} 1.0", "comment fuzz seed", f"element vertex {len(vertices)}",
            "property float x", "property float y", "property float z"]
    if extra:
        head += ["property uchar red"]
    head += [f"element face {len(faces)}", "property list uchar int vertex_indices"]
    if extra:
        head += ["element edge 1", "property int vertex1", "property list ushort short path"]
    head += ["end_header"]
    out = ("\n".join(head) + "\n").encode()
    if encoding == "ascii":
        for v in vertices:
            out += (" ".join(repr(c) for c in v) + (" 7" if extra else "") + "\n").encode()
        for f in faces:
            out += (" ".join(map(str, (len(f),) + tuple(f))) + "\n").encode()
        if extra:
            out += b"0 2 1 2\n"
        return out
    e = "<" if encoding == "binary_little_endian" else ">"
    for v in vertices:
        out += struct.pack(e + "3f", *v) + (b"\x07" if extra else b"")
    for f in faces:
        out += struct.pack(e + "B", len(f)) + struct.pack(e + f"{len(f)}i", *f)
    if extra:
        out += struct.pack(e + "iHhh", 0, 2, 1, 2)
    return out


def ply_seeds():
    for rel in ["bunny/bunny.ply", "dragon/dragon.ply"]:
        data = read(rel, 2 * 1024 * 1024)
        if not data:
            continue
        # The raw first KB (a header with counts the bytes cannot hold).
        put("ply", Path(rel).stem + "-prefix.ply", data[:1024])
        small = ply_small(data)
        if not small:
            continue
        vertices, faces = small
        for encoding in ["ascii", "binary_little_endian", "binary_big_endian"]:
            for extra in [False, True]:
                name = f"{Path(rel).stem}-{encoding}{'-extra' if extra else ''}.ply"
                put("ply", name, ply_write(vertices, faces, encoding, extra))


def scene_file_seeds():
    for path in sorted((REPO / "scenes").glob("*.toml")):
        put("scene_file", path.name, path.read_bytes())


def gltf_seeds():
    positions = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    indices = struct.pack("<3H", 0, 1, 2) + b"\0\0"
    blob = positions + indices
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "translation": [1, 2, 3], "children": [1]}, {"mesh": 0, "scale": [2, 2, 2]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0.2, 1]}}],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
    }
    text = dict(doc)
    text["buffers"] = [{"byteLength": len(blob),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]
    put("gltf", "triangle.gltf", json.dumps(text, indent=1))
    chunk = json.dumps(doc).encode()
    chunk += b" " * (-len(chunk) % 4)
    body = struct.pack("<II", len(chunk), 0x4E4F534A) + chunk + struct.pack("<II", len(blob), 0x004E4942) + blob
    put("gltf", "triangle.glb", struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
    # The material extensions and alpha modes the loader reads.
    ext = dict(text)
    ext["extensionsUsed"] = ["KHR_materials_ior", "KHR_materials_specular",
                             "KHR_materials_transmission", "KHR_materials_volume",
                             "KHR_materials_emissive_strength"]
    ext["materials"] = [
        {"pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0.2, 0.4], "metallicFactor": 0.3,
                                  "roughnessFactor": 0.2},
         "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": True,
         "extensions": {"KHR_materials_ior": {"ior": 1.7},
                        "KHR_materials_specular": {"specularFactor": 0.5,
                                                   "specularColorFactor": [1, 0.8, 0.6]},
                        "KHR_materials_emissive_strength": {"emissiveStrength": 4}}},
        {"alphaMode": "BLEND",
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                        "KHR_materials_volume": {"thicknessFactor": 0.1}}},
    ]
    ext["meshes"] = [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0},
                                     {"attributes": {"POSITION": 0}, "indices": 1, "material": 1}]}]
    put("gltf", "materials.gltf", json.dumps(ext, indent=1))


def png(width, height, colour_type, depth, rows):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    ihdr = struct.pack(">IIBBBBB", width, height, depth, colour_type, 0, 0, 0)
    raw = b"".join(b"\0" + r for r in rows)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def tga(kind, width, height, depth, descriptor, data, cmap=b"", cmap_bits=0, footer=True):
    header = struct.pack("<BBBHHBHHHHBB", 0, 1 if cmap else 0, kind, 0, len(cmap) // max(cmap_bits // 8, 1),
                         cmap_bits, 0, 0, width, height, depth, descriptor)
    tail = b"\0" * 8 + b"TRUEVISION-XFILE.\0" if footer else b""
    return header + cmap + data + tail


def image_seeds():
    # TGA: 24-bit raw bottom-up, 32-bit run-length top-down with alpha,
    # colour-mapped, 16-bit grey with alpha.
    put("image", "rgb24.tga", tga(2, 2, 2, 24, 0, bytes(range(12))))
    put("image", "rle32.tga", tga(10, 3, 2, 32, 0x28, bytes([0x82, 1, 2, 3, 128, 0x02, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0, 0, 0])))
    put("image", "mapped.tga", tga(1, 2, 1, 8, 0, bytes([0, 1]), cmap=bytes([255, 0, 0, 0, 255, 0]), cmap_bits=24))
    put("image", "grey16.tga", tga(3, 1, 2, 16, 0, bytes([10, 255, 200, 0])))
    # PFM: colour little-endian, grey big-endian with a scale.
    put("image", "rgb.pfm", b"PF\n2 1\n-1.0\n" + struct.pack("<6f", 0.5, 1, 2, 0, 0.25, 8))
    put("image", "grey.pfm", b"Pf\n1 2\n2.0\n" + struct.pack(">2f", 0.5, 3))
    put("image", "rgb.png", png(2, 2, 2, 8, [bytes([255, 0, 0, 0, 255, 0]), bytes([0, 0, 255, 9, 9, 9])]))
    put("image", "grey16.png", png(3, 1, 0, 16, [struct.pack(">3H", 0, 30000, 65535)]))
    put("image", "rgba.png", png(1, 2, 6, 8, [bytes([1, 2, 3, 4]), bytes([5, 6, 7, 8])]))
    put("image", "tiny.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n" + bytes([128, 64, 32, 129]) * 4)
    for rel in ["sponza/textures/00_skap.jpg"]:
        data = read(rel)
        if data:
            put("image", Path(rel).name, data)


def hand_made():
    for folder in sorted((FUZZ / "seeds").iterdir()):
        for path in sorted(folder.iterdir()):
            put(folder.name, path.name, path.read_bytes())


def main():
    for target in ["obj", "ply", "scene_file", "gltf", "image", "kdtree", "pbrt"]:
        (CORPUS / target).mkdir(parents=True, exist_ok=True)
    obj_seeds()
    ply_seeds()
    scene_file_seeds()
    gltf_seeds()
    image_seeds()
    hand_made()
    for target in sorted(p.name for p in CORPUS.iterdir()):
        print(f"make_seeds: corpus/{target}: {len(list((CORPUS / target).iterdir()))} files")


if __name__ == "__main__":
    main()
