#!/usr/bin/env python3
"""Writes the plain-format KTX2 textures of the KTX2 tests (plain_*.ktx2):
a 4 x 2 image whose texel i (row by row from the top left, i = 0..7)
holds, per format kind,

- 8-bit:  R = 32 i + 3, G = 255 - 30 i, B = 7 i^2 mod 256, A = 255 - 20 i
- 16-bit: each 8-bit code c above as 257 c + i
- float:  R = i / 2 + 1/4, G = 2 - i / 8, B = 16 i, A = i / 8

in the formats, supercompression schemes and shapes the tests read: the
base level (level 0) is read, whatever else the file holds (a second mip
level, a second array layer, both filled with other values). The level
data is compressed with the reference Zstandard library (PyPI's
`zstandard`) and Python's zlib; the layout (header, level index, data
format descriptor, key/value data, levels smallest first) follows the
KTX 2.0 specification as libktx's `ktx create` writes it.

    python3 -m venv venv && venv/bin/pip install zstandard && venv/bin/python make_ktx2_plain.py
"""

import math
import struct
import zlib

import zstandard

W, H = 4, 2
N = W * H
SIGNATURE = b"\xabKTX 20\xbb\r\n\x1a\n"
SCHEMES = {"none": 0, "zstd": 2, "zlib": 3}
# Data format descriptor channel ids (KHR_DF_CHANNEL_RGBSDA_*).
R, G, B, A = 0, 1, 2, 15


def codes8(i):
    return [32 * i + 3, 255 - 30 * i, (7 * i * i) % 256, 255 - 20 * i]


def values16(i):
    return [257 * c + i for c in codes8(i)]


def floats(i):
    return [i / 2 + 0.25, 2 - i / 8, 16.0 * i, i / 8]


def pack_e5b9g9r9(rgb):
    """The shared-exponent packing of Vulkan's E5B9G9R9_UFLOAT_PACK32."""
    top = max(rgb)
    exp = max(-16, math.floor(math.log2(top))) + 1 + 15 if top > 0 else 0
    scale = 2.0 ** (exp - 15 - 9)
    if round(top / scale) == 512:
        exp += 1
        scale *= 2
    m = [round(c / scale) for c in rgb]
    return m[0] | m[1] << 9 | m[2] << 18 | exp << 27


def small_float(v, mantissa_bits):
    """An unsigned float with a 5-bit exponent (bias 15), for values that
    fit exactly (the test image's are multiples of 1/8 below 128)."""
    if v == 0:
        return 0
    e = math.floor(math.log2(v))
    m = round((v / 2.0**e - 1) * (1 << mantissa_bits))
    assert m < (1 << mantissa_bits) and (1 + m / (1 << mantissa_bits)) * 2.0**e == v, v
    return (e + 15) << mantissa_bits | m


def texel(kind, i, channels, order):
    """Texel i's bytes in a format of `kind` with the channels `order`."""
    if kind == "u8":
        c = codes8(i)
        return bytes(c["RGBA".index(ch)] for ch in order)
    if kind == "u16":
        v = values16(i)
        return b"".join(struct.pack("<H", v["RGBA".index(ch)]) for ch in order)
    if kind == "f16":
        v = floats(i)
        return b"".join(struct.pack("<e", v["RGBA".index(ch)]) for ch in order)
    if kind == "f32":
        v = floats(i)
        return b"".join(struct.pack("<f", v["RGBA".index(ch)]) for ch in order)
    if kind == "e5b9g9r9":
        return struct.pack("<I", pack_e5b9g9r9(floats(i)[:3]))
    if kind == "b10g11r11":
        r, g, b = floats(i)[:3]
        return struct.pack("<I", small_float(r, 6) | small_float(g, 6) << 11 | small_float(b, 5) << 22)
    raise ValueError(kind)


def dfd(kind, order, srgb):
    """A basic data format descriptor: RGBSDA colour model, BT.709
    primaries, linear or sRGB transfer, one sample per channel."""
    sizes = {"u8": 8, "u16": 16, "f16": 16, "f32": 32}
    samples = []
    if kind in sizes:
        bits = sizes[kind]
        for k, ch in enumerate(order):
            qualifiers = 0x80 | 0x40 if kind in ("f16", "f32") else 0  # float, signed
            if ch == "A" and srgb:
                qualifiers |= 0x10  # linear alpha in an sRGB format
            channel = {"R": R, "G": G, "B": B, "A": A}[ch]
            word0 = k * bits | (bits - 1) << 16 | (channel | qualifiers) << 24
            if kind in ("f16", "f32"):
                lower, upper = 0xBF800000, 0x3F800000  # -1.0 and 1.0
            else:
                lower, upper = 0, (1 << bits) - 1
            samples.append(struct.pack("<4I", word0, 0, lower, upper))
        texel_bytes = len(order) * bits // 8
    else:
        fields = {"b10g11r11": [(0, 11, R), (11, 11, G), (22, 10, B)],
                  "e5b9g9r9": [(0, 9, R), (9, 9, G), (18, 9, B)]}[kind]
        for offset, length, channel in fields:
            samples.append(struct.pack("<4I", offset | (length - 1) << 16 | (channel | 0x80) << 24, 0, 0, 0x7F800000))
        texel_bytes = 4
    block = struct.pack(
        "<IIBBBBBBBB8B",
        0,  # vendor 0 (Khronos), descriptor type 0
        2 | (24 + 16 * len(samples)) << 16,  # version 2, block size
        1,  # colour model RGBSDA
        1,  # primaries BT.709
        2 if srgb else 1,  # transfer sRGB or linear
        0,  # flags: straight alpha
        0, 0, 0, 0,  # texel block dimensions 1x1x1x1
        texel_bytes, 0, 0, 0, 0, 0, 0, 0,
    ) + b"".join(samples)
    return struct.pack("<I", 4 + len(block)) + block


def kvd(pairs):
    out = b""
    for key, value in pairs:
        entry = key.encode() + b"\0" + value.encode() + b"\0"
        out += struct.pack("<I", len(entry)) + entry
        out += b"\0" * (-len(out) % 4)
    return out


def ktx2(vk_format, kind, order, srgb, scheme, type_size, levels=1, layers=0, swizzle=None):
    """The file: `levels` mip levels of `max(layers, 1)` layers each; the
    base level's first layer is the test image, everything else texel
    values of index 7 - i (so reading the wrong image shows)."""

    def image(w, h, first):
        return b"".join(texel(kind, (i if first else 7 - i) % N, len(order), order) for i in range(w * h))

    raw_levels = []
    for level in range(levels):
        w, h = max(W >> level, 1), max(H >> level, 1)
        raw_levels.append(b"".join(image(w, h, level == 0 and layer == 0) for layer in range(max(layers, 1))))
    pairs = [("KTXwriter", "make_ktx2_plain.py")]
    if swizzle:
        pairs.insert(0, ("KTXswizzle", swizzle))
    kv = kvd(pairs)
    df = dfd(kind, order, srgb)
    head_len = 80 + 24 * levels
    dfd_at = head_len
    kvd_at = dfd_at + len(df)
    packed = []
    for data in raw_levels:
        if scheme == "zstd":
            data = zstandard.ZstdCompressor(level=10).compress(data)
        elif scheme == "zlib":
            data = zlib.compress(data)
        packed.append(data)
    # Levels are stored smallest first, each aligned (lcm(texel size, 4),
    # or 1 with supercompression).
    align = 1 if scheme != "none" else 4 * type_size // math.gcd(4, type_size)
    body = bytearray()
    offsets = [0] * levels
    at = kvd_at + len(kv)
    for level in reversed(range(levels)):
        pad = -(at + len(body)) % align
        body += b"\0" * pad
        offsets[level] = at + len(body)
        body += packed[level]
    header = SIGNATURE + struct.pack(
        "<13I2Q",
        vk_format,
        type_size,
        W,
        H,
        0,
        layers,
        1,
        levels,
        SCHEMES[scheme],
        dfd_at,
        len(df),
        kvd_at,
        len(kv),
        0,
        0,
    )
    index = b"".join(
        struct.pack("<3Q", offsets[k], len(packed[k]), len(raw_levels[k])) for k in range(levels)
    )
    return header + index + df + kv + bytes(body)


FILES = {
    # Bevy's copy of the Khronos AnisotropyBarnLamp stores its normal and
    # occlusion/roughness/metal maps so.
    "plain_rgb8_zstd.ktx2": (23, "u8", "RGB", False, "zstd", 1, dict(levels=2)),
    "plain_rgba8_srgb_zlib.ktx2": (43, "u8", "RGBA", True, "zlib", 1, {}),
    "plain_bgra8_none.ktx2": (44, "u8", "BGRA", False, "none", 1, dict(layers=2)),
    "plain_r8_rrr1.ktx2": (9, "u8", "R", False, "none", 1, dict(swizzle="rrr1")),
    "plain_rg8_zstd.ktx2": (16, "u8", "RG", False, "zstd", 1, {}),
    "plain_rgba16_zstd.ktx2": (91, "u16", "RGBA", False, "zstd", 2, {}),
    "plain_rgb16_none.ktx2": (84, "u16", "RGB", False, "none", 2, {}),
    "plain_rgba16f_zlib.ktx2": (97, "f16", "RGBA", False, "zlib", 2, {}),
    "plain_rgb32f_zstd.ktx2": (106, "f32", "RGB", False, "zstd", 4, {}),
    "plain_r32f_none.ktx2": (100, "f32", "R", False, "none", 4, {}),
    "plain_e5b9g9r9_none.ktx2": (123, "e5b9g9r9", "RGB", False, "none", 4, {}),
    "plain_b10g11r11_zstd.ktx2": (122, "b10g11r11", "RGB", False, "zstd", 4, {}),
}

for name, (vk, kind, order, srgb, scheme, type_size, extra) in FILES.items():
    with open(name, "wb") as f:
        f.write(ktx2(vk, kind, order, srgb, scheme, type_size, **extra))
