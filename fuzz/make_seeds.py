#!/usr/bin/env python3
"""Builds the fuzz seed corpora in fuzz/corpus/<target>/ at run time.

Seeds are small files made from the benchmark meshes ($SAHARA_SCENES, else
../shared/scenes beside the repository; the Cornell box and the bunny PLY
fall back to the copies in scenes/assets): the Cornell box whole, the first lines of
the big OBJ files, PLY files cut down to their first vertices and the faces
among them (in every encoding), a tiny glTF and GLB, tiny PNG/HDR images, the
KTX2 test textures and a small JPEG texture; plus the hand-made seeds in fuzz/seeds/<target>/. Nothing
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
    put("gltf", "extensions.gltf", json.dumps(extensions_doc(), indent=1))
    # What the loader refuses by name: glTF 1.0, and required compression.
    put("gltf", "gltf1.gltf", json.dumps({"asset": {"version": "1.0"}, "meshes": {"m": {}}}))
    draco = dict(text)
    draco["extensionsUsed"] = ["KHR_draco_mesh_compression", "KHR_materials_sheen"]
    draco["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    put("gltf", "draco.gltf", json.dumps(draco, indent=1))


def extensions_doc():
    """A quad with every texture role, sampler wrap modes, texture
    transforms, two uv sets, tangents, quantized positions
    (KHR_mesh_quantization), a clear coat, punctual lights, cameras and an
    unsupported optional extension."""
    # Positions as unnormalized shorts, uvs as normalized unsigned shorts,
    # normals as normalized bytes, tangents as floats.
    positions = struct.pack("<16h", 0, 0, 0, 0, 1, 0, 0, 0, 1, 1, 0, 0, 0, 1, 0, 0)
    uv0 = struct.pack("<8H", 0, 0, 65535, 0, 65535, 65535, 0, 65535)
    uv1 = struct.pack("<8f", 0, 0, 2, 0, 2, 2, 0, 2)
    normals = struct.pack("<16b", *([0, 0, 127, 0] * 4))
    tangents = struct.pack("<16f", *([1, 0, 0, 1] * 4))
    indices = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    blob = positions + uv0 + uv1 + normals + tangents + indices
    views, offset = [], 0
    for part, stride in [(positions, 8), (uv0, 4), (uv1, 8), (normals, 4), (tangents, 16), (indices, None)]:
        view = {"buffer": 0, "byteOffset": offset, "byteLength": len(part)}
        if stride:
            view["byteStride"] = stride
        views.append(view)
        offset += len(part)
    image = png(2, 2, 6, 8, [bytes([255, 128, 0, 255, 0, 255, 128, 128]), bytes([128, 128, 255, 255, 9, 9, 9, 0])])

    def tex(index, **kw):
        info = {"index": index}
        info.update(kw)
        return info

    transform = {"KHR_texture_transform": {"offset": [0.5, 0.25], "rotation": 0.3, "scale": [2, 3], "texCoord": 1}}
    return {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_texture_transform", "KHR_materials_clearcoat", "KHR_lights_punctual",
                           "KHR_mesh_quantization", "KHR_materials_emissive_strength", "KHR_materials_sheen"],
        "extensionsRequired": ["KHR_mesh_quantization", "KHR_texture_transform"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.9, 0.8], "intensity": 100, "range": 10},
            {"type": "spot", "intensity": 500, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
            {"type": "directional", "intensity": 3000}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3, 4, 5]}],
        "nodes": [
            {"mesh": 0, "scale": [0.001, 0.001, 0.001]},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 2, 0]},
            {"extensions": {"KHR_lights_punctual": {"light": 1}}, "rotation": [-0.7071, 0, 0, 0.7071]},
            {"extensions": {"KHR_lights_punctual": {"light": 2}}},
            {"camera": 0, "translation": [0, 0, 3], "name": "front"},
            {"camera": 1, "translation": [0, 3, 0]},
        ],
        "cameras": [
            {"type": "perspective", "name": "front", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}},
            {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2,
                                                   "NORMAL": 3, "TANGENT": 4},
                                    "indices": 5, "material": 0}]}],
        "materials": [{
            "pbrMetallicRoughness": {"baseColorTexture": tex(0), "metallicRoughnessTexture": tex(1, texCoord=1),
                                     "metallicFactor": 0.5, "roughnessFactor": 0.7},
            "normalTexture": tex(2, scale=0.8, extensions=transform),
            "occlusionTexture": tex(0, strength=0.5),
            "emissiveTexture": tex(1),
            "emissiveFactor": [1, 1, 1],
            "extensions": {
                "KHR_materials_emissive_strength": {"emissiveStrength": 3},
                "KHR_materials_clearcoat": {"clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 0.1,
                                            "clearcoatTexture": tex(0), "clearcoatRoughnessTexture": tex(1),
                                            "clearcoatNormalTexture": tex(2)},
                "KHR_materials_sheen": {"sheenColorFactor": [1, 0, 0]}},
        }],
        "textures": [{"source": 0, "sampler": 0}, {"source": 0, "sampler": 1}, {"source": 0}],
        "samplers": [{"wrapS": 33071, "wrapT": 33648}, {"wrapS": 10497, "wrapT": 33071}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(image).decode()}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5122, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "normalized": True, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5120, "normalized": True, "count": 4, "type": "VEC3"},
            {"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC4"},
            {"bufferView": 5, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }


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
    # KTX2 with Basis Universal payloads (UASTC with Zstandard, ETC1S), and
    # plain formats (8-bit with Zstandard, half floats with zlib, 16-bit
    # stored as is, a packed float format).
    for name in ["quad_uastc.ktx2", "quad_etc1s.ktx2", "plain_rgb8_zstd.ktx2", "plain_rgba16f_zlib.ktx2",
                 "plain_rgb16_none.ktx2", "plain_e5b9g9r9_none.ktx2"]:
        put("image", name, (REPO / "crates/sahara-readers/tests/data" / name).read_bytes())
    for rel in ["sponza/textures/00_skap.jpg"]:
        data = read(rel)
        if data:
            put("image", Path(rel).name, data)


def hand_made():
    for folder in sorted((FUZZ / "seeds").iterdir()):
        for path in sorted(folder.iterdir()):
            put(folder.name, path.name, path.read_bytes())


def main():
    for target in ["obj", "ply", "scene_file", "gltf", "image", "kdtree", "pbrt", "mitsuba"]:
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
