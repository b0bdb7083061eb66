#!/usr/bin/env python3
"""Writes the KTX2 textures of the KTX2 tests: an 8 x 8 image of four 4 x 4
quadrants (red, green / blue, white; opaque), encoded with Basis Universal
as UASTC with Zstandard supercompression (quad_uastc.ktx2) and as ETC1S
with BasisLZ (quad_etc1s.ktx2), the two payloads of KHR_texture_basisu,
and quad_basisu.gltf, a square textured with the UASTC one through
KHR_texture_basisu alone (no PNG fallback).

Needs alktx2 (PyPI), which wraps the reference Basis Universal encoder:
python3 -m venv venv && venv/bin/pip install alktx2 && venv/bin/python make_ktx2.py
The reference transcoder decodes them (alktx2.decode_ktx2_to_bytes) to the
texels the tests expect: UASTC exactly the colours above; ETC1S red
(253, 0, 0), green (2, 255, 2), blue (0, 0, 253) and white.
"""

import base64
import json
import struct

import alktx2

W = H = 8
COLOURS = {(0, 0): (255, 0, 0), (1, 0): (0, 255, 0), (0, 1): (0, 0, 255), (1, 1): (255, 255, 255)}

pixels = bytearray()
for y in range(H):
    for x in range(W):
        pixels += bytes(COLOURS[(x // 4, y // 4)]) + b"\xff"

uastc = alktx2.encode_raw_rgba_to_ktx2(
    bytes(pixels), W, H, False, codec="uastc", srgb=True, zstd_supercompression_level=3
)
etc1s = alktx2.encode_raw_rgba_to_ktx2(bytes(pixels), W, H, False, codec="etc1s", quality=255, srgb=True)
open("quad_uastc.ktx2", "wb").write(uastc)
open("quad_etc1s.ktx2", "wb").write(etc1s)

# A unit square in z = 0 with uvs matching the image (v down), textured.
pos = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
bin_ = b"".join(struct.pack("<3f", *p) for p in pos)
bin_ += b"".join(struct.pack("<2f", *t) for t in uv)
bin_ += struct.pack("<6H", 0, 1, 2, 0, 2, 3)
doc = {
    "asset": {"version": "2.0", "generator": "make_ktx2.py"},
    "extensionsUsed": ["KHR_texture_basisu"],
    "extensionsRequired": ["KHR_texture_basisu"],
    "buffers": [
        {
            "byteLength": len(bin_),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(bin_).decode(),
        }
    ],
    "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": 48},
        {"buffer": 0, "byteOffset": 48, "byteLength": 32},
        {"buffer": 0, "byteOffset": 80, "byteLength": 12},
    ],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
    ],
    "images": [{"uri": "quad_uastc.ktx2", "mimeType": "image/ktx2"}],
    "textures": [{"extensions": {"KHR_texture_basisu": {"source": 0}}}],
    "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
    "nodes": [{"mesh": 0}],
    "scenes": [{"nodes": [0]}],
    "scene": 0,
}
with open("quad_basisu.gltf", "w") as f:
    json.dump(doc, f, indent=1)
    f.write("\n")
