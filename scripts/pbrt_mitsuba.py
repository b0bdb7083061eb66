#!/usr/bin/env python3
"""A pbrt-v4 scene file as a Mitsuba 3 scene, for an independent renderer's image of the same file.

Reads the subset of pbrt-v4 that Bitterli's scenes (as written for pbrt-v4) use: a camera given by a
`Transform` and a perspective `fov`, `Film` resolution, `Integrator` `maxdepth`, `Texture` imagemaps,
`MakeNamedMaterial` / `NamedMaterial` / `Material` of types `diffuse` (rgb or texture reflectance),
`conductor` (rgb `eta`, `k`, `uroughness` / `vroughness`, `remaproughness`), `dielectric` (`eta`,
smooth), `AreaLightSource "diffuse"` (`L`, `scale`, `twosided`), `Shape` `plymesh` and `trianglemesh`
(written to PLY files in a work folder), `Transform`, `ConcatTransform`, `Translate`, `Scale`,
`AttributeBegin` / `AttributeEnd`, `ReverseOrientation`. Anything else is an error, so that a
comparison never rests on a silent difference.

What maps how: pbrt's diffuse and conductor are two-sided (Mitsuba's `twosided`); a conductor is
Mitsuba's `roughconductor` with GGX (pbrt-v4 has no other distribution), `alpha = sqrt(r)` when
`remaproughness` is true (pbrt-v4's default), else `r`, or a smooth `conductor` when alpha is 0;
pbrt's `maxdepth` d is Mitsuba's `max_depth` d + 1; the camera is pbrt's, mirrored in x (pbrt's
camera space is left-handed), with `fov` on the smaller axis. A texture whose file is missing, or
named in `textures`, becomes the constant given there (default grey 0.5, as Sahara reads a missing
image).

usage: python3 scripts/pbrt_mitsuba.py SCENE.pbrt --spp N --width W --height H -o OUT.exr [--depth D]
       (or, from Python: scene(path, spp, width, height, work) -> a dict for mi.load_dict)
"""
import argparse
import math
import os
import re
import struct
import sys
import tempfile

import numpy as np

TOKEN = re.compile(r'"[^"]*"|\[|\]|#[^\n]*|[^\s\[\]"#]+')


def tokens(text):
    for t in TOKEN.findall(text):
        if not t.startswith("#"):
            yield t


def parse(path):
    """The file's directives: a list of (name, [positional values], {"type name": [values]})."""
    toks = list(tokens(open(path).read()))
    out, i = [], 0

    def value(t):
        if t.startswith('"'):
            return t[1:-1]
        if t in ("true", "false"):
            return t == "true"
        return float(t)

    while i < len(toks):
        name = toks[i]
        i += 1
        pos, params = [], {}
        while i < len(toks) and (toks[i].startswith('"') or toks[i] == "[" or
                                 re.match(r"^[-+.\d]", toks[i])):
            t = toks[i]
            if t.startswith('"') and len(t.strip('"').split()) == 2:
                key = t.strip('"')
                i += 1
                if toks[i] == "[":
                    i += 1
                    vals = []
                    while toks[i] != "]":
                        vals.append(value(toks[i]))
                        i += 1
                    i += 1
                else:
                    vals = [value(toks[i])]
                    i += 1
                params[key] = vals
            elif t == "[":
                i += 1
                while toks[i] != "]":
                    pos.append(value(toks[i]))
                    i += 1
                i += 1
            else:
                pos.append(value(t))
                i += 1
        out.append((name, pos, params))
    return out


def get(params, name, default=None):
    for key, vals in params.items():
        if key.split()[1] == name:
            return vals
    return default


def write_ply(path, p, idx, n=None, uv=None):
    nv = len(p) // 3
    head = ["ply", "format binary_little_endian 1.0", f"element vertex {nv}",
            "property float x", "property float y", "property float z"]
    cols = [np.asarray(p, np.float32).reshape(nv, 3)]
    if n:
        head += ["property float nx", "property float ny", "property float nz"]
        cols.append(np.asarray(n, np.float32).reshape(nv, 3))
    if uv:
        head += ["property float u", "property float v"]
        cols.append(np.asarray(uv, np.float32).reshape(nv, 2))
    tri = np.asarray(idx, np.int32).reshape(-1, 3)
    head += [f"element face {len(tri)}", "property list uchar int vertex_indices", "end_header"]
    with open(path, "wb") as f:
        f.write(("\n".join(head) + "\n").encode())
        f.write(np.concatenate(cols, 1).astype("<f4").tobytes())
        for t in tri:
            f.write(struct.pack("<B3i", 3, *t))


def matrix(vals):
    """pbrt's `Transform` values (column-major) as a 4 x 4 matrix."""
    return np.asarray(vals, np.float64).reshape(4, 4).T


def scene(path, spp, width=None, height=None, work=None, depth=None, textures=None,
          integrator="path"):
    """The pbrt file at `path` as a dict for Mitsuba 3's `load_dict` (variant set by the caller)."""
    import mitsuba as mi
    folder = os.path.dirname(os.path.abspath(path))
    work = work or tempfile.mkdtemp()
    textures = textures or {}
    ctm = np.eye(4)
    stack = []
    camera_from_world = None
    fov = 90.0
    res = [1280, 720]
    maxdepth = 5
    tex, mats = {}, {}
    cur_mat, area, reverse = None, None, False
    d = {"type": "scene"}
    count = 0

    def material(kind, params):
        if kind == "diffuse":
            r = get(params, "reflectance", [0.5])
            key = [k for k in params if k.endswith(" reflectance")]
            if key and key[0].startswith("texture"):
                refl = tex[r[0]]
            else:
                refl = {"type": "rgb", "value": r if len(r) == 3 else r * 3}
            return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": refl}}
        if kind == "conductor":
            ur = get(params, "uroughness", get(params, "roughness", [0.0]))[0]
            vr = get(params, "vroughness", get(params, "roughness", [0.0]))[0]
            remap = get(params, "remaproughness", [True])[0]
            a = [math.sqrt(x) if remap else x for x in (ur, vr)]
            eta = {"type": "rgb", "value": get(params, "eta")}
            k = {"type": "rgb", "value": get(params, "k")}
            if a[0] == 0 and a[1] == 0:
                b = {"type": "conductor", "eta": eta, "k": k}
            else:
                b = {"type": "roughconductor", "distribution": "ggx", "alpha_u": a[0],
                     "alpha_v": a[1], "eta": eta, "k": k}
            return {"type": "twosided", "bsdf": b}
        if kind == "dielectric":
            r = get(params, "roughness", [0.0])[0]
            if r:
                sys.exit(f"{path}: rough dielectric not mapped")
            return {"type": "dielectric", "int_ior": get(params, "eta", [1.5])[0], "ext_ior": 1.0}
        sys.exit(f"{path}: material {kind} not mapped")

    for name, pos, params in parse(path):
        if name == "Integrator":
            maxdepth = int(get(params, "maxdepth", [5])[0])
        elif name in ("Sampler", "PixelFilter", "WorldBegin", "ColorSpace", "Option"):
            if name == "WorldBegin":
                ctm = np.eye(4)
        elif name == "Film":
            res = [int(get(params, "xresolution", [1280])[0]), int(get(params, "yresolution", [720])[0])]
        elif name == "Camera":
            camera_from_world = ctm.copy()
            fov = get(params, "fov", [90.0])[0]
        elif name == "Transform":
            ctm = matrix(pos)
        elif name == "ConcatTransform":
            ctm = ctm @ matrix(pos)
        elif name == "Translate":
            t = np.eye(4)
            t[:3, 3] = pos
            ctm = ctm @ t
        elif name == "Scale":
            ctm = ctm @ np.diag(list(pos) + [1.0])
        elif name == "AttributeBegin":
            stack.append((ctm.copy(), cur_mat, area, reverse))
        elif name == "AttributeEnd":
            ctm, cur_mat, area, reverse = stack.pop()
        elif name == "ReverseOrientation":
            reverse = not reverse
        elif name == "Texture":
            tname, _, ttype = pos[:3]
            if ttype != "imagemap":
                sys.exit(f"{path}: texture {ttype} not mapped")
            fname = get(params, "filename")[0]
            full = os.path.join(folder, fname)
            if tname in textures or not os.path.exists(full):
                v = textures.get(tname, 0.5)
                tex[tname] = {"type": "rgb", "value": [v] * 3 if np.isscalar(v) else v}
            else:
                tex[tname] = {"type": "bitmap", "filename": full, "filter_type": "bilinear"}
        elif name == "MakeNamedMaterial":
            mats[pos[0]] = material(get(params, "type")[0], params)
        elif name == "NamedMaterial":
            cur_mat = mats[pos[0]]
        elif name == "Material":
            cur_mat = material(pos[0], params)
        elif name == "AreaLightSource":
            if get(params, "twosided", [False])[0]:
                sys.exit(f"{path}: two-sided area light not mapped")
            L = np.asarray(get(params, "L"), np.float64) * get(params, "scale", [1.0])[0]
            area = {"type": "area", "radiance": {"type": "rgb", "value": list(L)}}
        elif name == "Shape":
            if pos[0] == "plymesh":
                fname = os.path.join(folder, get(params, "filename")[0])
            elif pos[0] == "trianglemesh":
                fname = os.path.join(work, f"mesh{count}.ply")
                write_ply(fname, get(params, "P"), get(params, "indices"), get(params, "N"),
                          get(params, "uv"))
            else:
                sys.exit(f"{path}: shape {pos[0]} not mapped")
            s = {"type": "ply", "filename": fname, "to_world": mi.ScalarTransform4f(ctm.tolist()),
                 "bsdf": cur_mat, "flip_normals": reverse}
            if area is not None:
                s["emitter"] = area
            d[f"shape{count}"] = s
            count += 1
        else:
            sys.exit(f"{path}: directive {name} not mapped")
    w, h = width or res[0], height or res[1]
    to_world = np.linalg.inv(camera_from_world) @ np.diag([-1.0, 1.0, 1.0, 1.0])
    d["sensor"] = {
        "type": "perspective", "fov": fov, "fov_axis": "smaller",
        "to_world": mi.ScalarTransform4f(to_world.tolist()),
        "sampler": {"type": "independent", "sample_count": spp},
        "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "tent"},
                 "pixel_format": "rgb"},
    }
    d["integrator"] = {"type": integrator, "max_depth": (depth or maxdepth) + 1}
    return d


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--width", type=int)
    ap.add_argument("--height", type=int)
    ap.add_argument("--depth", type=int, help="pbrt's maxdepth instead of the file's")
    ap.add_argument("--integrator", default="path", help="Mitsuba's integrator (path, ptracer)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("-o", "--output", required=True)
    args = ap.parse_args()
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    with tempfile.TemporaryDirectory() as work:
        s = mi.load_dict(scene(args.scene, args.spp, args.width, args.height, work, args.depth,
                               integrator=args.integrator))
        img = mi.render(s, spp=args.spp, seed=args.seed)
    mi.Bitmap(img).write(args.output)


if __name__ == "__main__":
    main()
