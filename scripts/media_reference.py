#!/usr/bin/env python3
"""Reference images of Sahara's participating media, rendered by Mitsuba 3 (an independent renderer).

Each case is one small scene written twice from one description: as a Mitsuba 3 scene (rendered here
with its `volpath` integrator into a reference EXR) and as a Sahara scene file, with the density grid a
`.vol` file both read. The test `crates/sahara-formats/tests/formats/media_reference.rs` renders the
Sahara file and holds it to the reference per channel and per block (docs/renderer.md, "How media are
tested").

- `fog_box`: a box room (grey floor, back wall and ceiling, red and green side walls) lit by a square
  area light under its ceiling and filled with homogeneous fog (sigma_t 0.3, albedo 0.8, HG g 0.3),
  bounded by a box without a material that holds the light too. (With the light just above the fog's
  top face, Mitsuba 3.9.1's `volpath` renders the fog near the top up to 8x darker than Sahara does, and
  Sahara agrees there with the single-scattering integral computed numerically; the light inside the
  fog keeps the comparison to what both renderers agree is right.)
- `sss_sphere`: a glass sphere (index 1.5) holding a scattering medium (sigma_t 2, albedo 0.9, HG g 0.7)
  on a grey floor, under a square area light and a dim environment: light enters by refraction only.
- `grid_blob`: a smooth blob of density on a 32^3 grid (written here as `grid_blob.vol`), coloured
  albedo, under a square light and an environment, bounded by its grid's box.
- `colour_blob`: the blob with colours per voxel: its extinction a three-channel 32^3 grid whose
  channels ramp differently across it (`colour_blob_sigma_t.vol`), its albedo a three-channel 16^3
  grid of its own (`colour_blob_albedo.vol`). This case is written as one Mitsuba XML file,
  `colour_blob.xml`, which Mitsuba renders here and Sahara's Mitsuba reader reads in the test.

Sahara's `max_depth` D is Mitsuba's D + 1 (Mitsuba counts the emitter hit as a bounce); both run
unidirectional volumetric path tracing with light sampling and MIS, box filter, 64 x 64 pixels.

usage (Mitsuba 3.9.1 from PyPI: `python3 -m venv V && V/bin/pip install mitsuba==3.9.1 numpy OpenEXR`):
    V/bin/python scripts/media_reference.py [--spp N] [--only NAME,...] [--scenes-only] [OUTDIR]
OUTDIR defaults to crates/sahara-formats/tests/media_reference.
"""
import argparse
import os
import struct

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_OUT = os.path.join(ROOT, "crates", "sahara-formats", "tests", "media_reference")

SIZE = 64
MAX_DEPTH = 24                # Sahara's; Mitsuba renders with MAX_DEPTH + 1
GREY = (0.5, 0.5, 0.5)
LIGHT = (12.0, 11.0, 10.0)


def grid_blob(n=32):
    """A smooth blob: density 1 - 4 r^2 (r from the cube's centre, in units of its side) where positive,
    a little lopsided so that the grid's orientation matters."""
    c = (np.arange(n) + 0.5) / n - 0.5
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    r2 = (x - 0.08) ** 2 + y ** 2 + (z + 0.05) ** 2 * 1.4
    return np.clip(1.0 - 4.0 * r2, 0.0, None).astype(np.float32)


def colour_field(n, colour):
    """`colour(x, y, z)` at the voxels' centres in the unit cube: an array (z, y, x, channel)."""
    c = (np.arange(n) + 0.5) / n
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    return np.stack(colour(x, y, z), axis=-1)


def colour_blob(n, colour):
    """The blob (`grid_blob`) times a colour per voxel (`colour_field`)."""
    return grid_blob(n)[..., None] * colour_field(n, colour)


def write_vol(path, values, lo, hi):
    """Mitsuba's `.vol` format, version 3, 32-bit floats, one channel ((z, y, x) array) or three
    ((z, y, x, 3), interleaved), x fastest."""
    nz, ny, nx = values.shape[:3]
    channels = values.shape[3] if values.ndim == 4 else 1
    with open(path, "wb") as f:
        f.write(b"VOL" + bytes([3]))
        f.write(struct.pack("<iiiii", 1, nx, ny, nz, channels))
        f.write(struct.pack("<6f", *lo, *hi))
        f.write(values.astype("<f4").tobytes())


# colour_blob's grids: extinction (times its scale) and albedo, each a colour per voxel.
COLOUR_SIGMA_T = lambda x, y, z: (0.6 + 0.8 * x, np.ones_like(x), 1.4 - 0.8 * y)
COLOUR_ALBEDO = lambda x, y, z: (np.full_like(x, 0.95), 0.5 + 0.45 * x, 0.9 - 0.5 * z)


def colour_blob_xml(case, out, spp, seed, size=SIZE):
    """`colour_blob` as a Mitsuba 3 XML scene (the files it names beside it in `out`)."""
    eye, target, vfov = case["camera"]
    lo, hi = (np.array(v, float) for v in case["medium"]["bound"][1:])
    vec = lambda v: ", ".join(repr(float(x)) for x in v)
    mat = lambda m: '<transform name="to_world"><matrix value="' + " ".join(
        repr(float(x)) for x in np.asarray(m).reshape(-1)) + '"/></transform>'
    rgb = lambda name, c: f'<rgb name="{name}" value="{vec(c)}"/>'

    def rect(corner, u, v):
        c, u, v = (np.array(g, float) for g in (corner, u, v))
        n = np.cross(u, v)
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n / np.linalg.norm(n), c + (u + v) / 2
        return mat(m)

    box = np.eye(4)
    box[:3, :3] = np.diag(hi - lo)
    box[:3, 3] = lo
    cube = np.eye(4)
    cube[:3, :3] = np.diag((hi - lo) / 2)
    cube[:3, 3] = (lo + hi) / 2
    m = case["medium"]
    lines = [
        '<scene version="3.0.0">',
        f'<integrator type="volpath"><integer name="max_depth" value="{MAX_DEPTH + 1}"/>'
        f'<integer name="rr_depth" value="{MAX_DEPTH + 1}"/></integrator>',
        '<sensor type="perspective"><string name="fov_axis" value="y"/>'
        f'<float name="fov" value="{vfov!r}"/>'
        f'<transform name="to_world"><lookat origin="{vec(eye)}" target="{vec(target)}" up="0, 1, 0"/></transform>'
        f'<sampler type="independent"><integer name="sample_count" value="{spp}"/>'
        f'<integer name="seed" value="{seed}"/></sampler>'
        f'<film type="hdrfilm"><integer name="width" value="{size}"/><integer name="height" value="{size}"/>'
        '<string name="pixel_format" value="rgb"/><rfilter type="box"/></film></sensor>',
        f'<emitter type="constant">{rgb("radiance", case["environment"])}</emitter>',
    ]
    for shape, geo, colour in case["objects"]:
        lines.append(f'<shape type="rectangle">{rect(*geo)}'
                     f'<bsdf type="twosided"><bsdf type="diffuse">{rgb("reflectance", colour)}</bsdf></bsdf></shape>')
    corner, eu, ev, radiance = case["light"]
    lines.append(f'<shape type="rectangle">{rect(corner, eu, ev)}'
                 f'<bsdf type="diffuse">{rgb("reflectance", (0, 0, 0))}</bsdf>'
                 f'<emitter type="area">{rgb("radiance", radiance)}</emitter></shape>')
    grid = lambda name, file: (f'<volume type="gridvolume" name="{name}"><string name="filename" value="{file}"/>'
                               f'<string name="filter_type" value="trilinear"/>{mat(box)}</volume>')
    lines += [
        f'<shape type="cube">{mat(cube)}<bsdf type="null"/>',
        f'<medium type="heterogeneous" name="interior"><phase type="hg"><float name="g" value="{m["g"]!r}"/></phase>',
        f'<float name="scale" value="{m["sigma_t"]!r}"/>',
        grid("sigma_t", "colour_blob_sigma_t.vol"), grid("albedo", "colour_blob_albedo.vol"),
        '</medium></shape>', '</scene>', ''
    ]
    lo_hi = (lo, hi)
    write_vol(os.path.join(out, "colour_blob_sigma_t.vol"), colour_blob(32, COLOUR_SIGMA_T), *lo_hi)
    write_vol(os.path.join(out, "colour_blob_albedo.vol"), colour_field(16, COLOUR_ALBEDO), *lo_hi)
    return "\n".join(lines)


def cases():
    """name -> the scene as plain values."""
    room = [("quad", ((-2, 0, 2), (4, 0, 0), (0, 0, -4)), GREY),           # floor
            ("quad", ((-2, 0, -2), (4, 0, 0), (0, 2, 0)), GREY),           # back wall
            ("quad", ((-2, 2, 2), (0, 0, -4), (4, 0, 0)), GREY),           # ceiling
            ("quad", ((-2, 0, 2), (0, 0, -4), (0, 2, 0)), (0.6, 0.1, 0.1)),  # left, red
            ("quad", ((2, 0, -2), (0, 0, 4), (0, 2, 0)), (0.1, 0.5, 0.1))]   # right, green
    floor = [("quad", ((-6, 0, 6), (12, 0, 0), (0, 0, -12)), GREY)]
    return {
        "fog_box": {
            "camera": ((0.0, 1.0, 4.4), (0.0, 1.0, 0.0), 42.0),
            "objects": room,
            "light": ((-0.4, 1.98, -0.4), (0.8, 0, 0), (0, 0, 0.8), LIGHT),
            "environment": None,
            "medium": {"kind": "homogeneous", "sigma_t": 0.3, "albedo": (0.8, 0.8, 0.8), "g": 0.3,
                       "bound": ("box", (-1.99, 0.01, -1.99), (1.99, 1.995, 1.99)), "glass": None},
        },
        "sss_sphere": {
            "camera": ((0.0, 1.6, 4.2), (0.0, 0.8, 0.0), 36.0),
            "objects": floor,
            "light": ((-1.5, 4.0, -0.5), (1.5, 0, 0), (0, 0, 1.5), (9.0, 9.0, 9.0)),
            "environment": (0.2, 0.22, 0.25),
            "medium": {"kind": "homogeneous", "sigma_t": 2.0, "albedo": (0.9, 0.9, 0.9), "g": 0.7,
                       "bound": ("sphere", (0.0, 1.0, 0.0), 1.0), "glass": 1.5},
        },
        "grid_blob": {
            "camera": ((0.0, 1.4, 4.0), (0.0, 0.9, 0.0), 38.0),
            "objects": floor,
            "light": ((-1.0, 4.0, 0.0), (1.2, 0, 0), (0, 0, 1.2), (12.0, 12.0, 12.0)),
            "environment": (0.3, 0.35, 0.45),
            "medium": {"kind": "grid", "sigma_t": 6.0, "albedo": (0.95, 0.85, 0.7), "g": 0.2,
                       "bound": ("box", (-1.0, 0.02, -1.0), (1.0, 2.02, 1.0)), "glass": None},
        },
        "colour_blob": {
            "camera": ((0.0, 1.4, 4.0), (0.0, 0.9, 0.0), 38.0),
            "objects": floor,
            "light": ((-1.0, 4.0, 0.0), (1.2, 0, 0), (0, 0, 1.2), (12.0, 12.0, 12.0)),
            "environment": (0.3, 0.35, 0.45),
            "medium": {"kind": "colour", "sigma_t": 6.0, "g": 0.2,
                       "bound": ("box", (-1.0, 0.02, -1.0), (1.0, 2.02, 1.0)), "glass": None},
        },
    }


def fmt(t):
    return "[" + ", ".join(f"{float(x)!r}" for x in t) + "]"


def sahara_scene(name, case):
    eye, target, vfov = case["camera"]
    m = case["medium"]
    sigma_t, albedo = m["sigma_t"], np.array(m["albedo"], float)
    lines = [
        f"# Media reference scene '{name}': written by scripts/media_reference.py; Mitsuba 3 rendered {name}.exr",
        "[camera]", f"eye = {fmt(eye)}", f"target = {fmt(target)}", f"vfov = {vfov!r}", "",
        "[film]", f"width = {SIZE}", f"height = {SIZE}", "",
        "[filter]", 'name = "box"', "",
        "[integrator]", 'name = "path"', f"max_depth = {MAX_DEPTH}", f"rr_depth = {MAX_DEPTH}", "",
        "[[medium]]", 'name = "inside"', f'type = "{m["kind"]}"',
        f"sigma_s = {fmt(albedo * sigma_t)}", f"sigma_a = {fmt((1 - albedo) * sigma_t)}", f"g = {m['g']!r}",
    ]
    bound = m["bound"]
    if m["kind"] == "grid":
        lines += [f'file = "{name}.vol"', f"min = {fmt(bound[1])}", f"max = {fmt(bound[2])}"]
    lines.append("")
    for i, (shape, geo, colour) in enumerate(case["objects"]):
        lines += ["[[material]]", f'name = "m{i}"', 'type = "diffuse"', f"albedo = {fmt(colour)}", "",
                  "[[object]]", 'type = "quad"', f"corner = {fmt(geo[0])}", f"edge_u = {fmt(geo[1])}",
                  f"edge_v = {fmt(geo[2])}", f'material = "m{i}"', ""]
    if m["glass"] is not None:
        lines += ["[[material]]", 'name = "glass"', 'type = "dielectric"', f"ior = {m['glass']!r}", ""]
    lines += ["[[object]]"]
    if bound[0] == "box":
        lines += ['type = "box"', f"min = {fmt(bound[1])}", f"max = {fmt(bound[2])}"]
    else:
        lines += ['type = "sphere"', f"center = {fmt(bound[1])}", f"radius = {bound[2]!r}"]
    if m["glass"] is not None:
        lines += ['material = "glass"']
    lines += ['medium_inside = "inside"', ""]
    corner, eu, ev, radiance = case["light"]
    lines += ["[[light]]", 'type = "area"', 'shape = "quad"', f"corner = {fmt(corner)}", f"edge_u = {fmt(eu)}",
              f"edge_v = {fmt(ev)}", f"radiance = {fmt(radiance)}", "two_sided = false", ""]
    if case["environment"] is not None:
        lines += ["[[light]]", 'type = "environment"', f"radiance = {fmt(case['environment'])}", ""]
    return "\n".join(lines)


def rectangle(T, corner, u, v):
    """Mitsuba's rectangle ([-1, 1]^2 in z = 0, normal +z) mapped onto corner + s u + t v, normal u x v."""
    c, u, v = (np.array(g, float) for g in (corner, u, v))
    n = np.cross(u, v)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n / np.linalg.norm(n), c + (u + v) / 2
    return T(m.tolist())


def mitsuba_scene(mi, name, case, out, spp, seed, size=SIZE):
    eye, target, vfov = case["camera"]
    rgb = lambda c: {"type": "rgb", "value": [float(x) for x in c]}
    T = mi.ScalarTransform4f
    scene = {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": MAX_DEPTH + 1, "rr_depth": MAX_DEPTH + 1},
        "sensor": {
            "type": "perspective", "fov_axis": "y", "fov": vfov, "near_clip": 1e-3,
            "to_world": T().look_at(origin=eye, target=target, up=(0, 1, 0)),
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
            "film": {"type": "hdrfilm", "width": size, "height": size, "pixel_format": "rgb",
                     "rfilter": {"type": "box"}},
        },
    }
    if case["environment"] is not None:
        scene["env"] = {"type": "constant", "radiance": rgb(case["environment"])}
    for i, (shape, geo, colour) in enumerate(case["objects"]):
        scene[f"object{i}"] = {"type": "rectangle", "to_world": rectangle(T, *geo),
                               "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": rgb(colour)}}}
    corner, eu, ev, radiance = case["light"]
    scene["light"] = {"type": "rectangle", "to_world": rectangle(T, corner, eu, ev),
                      "bsdf": {"type": "diffuse", "reflectance": rgb((0, 0, 0))},
                      "emitter": {"type": "area", "radiance": rgb(radiance)}}
    m = case["medium"]
    phase = {"type": "hg", "g": m["g"]}
    bound = m["bound"]
    if m["kind"] == "grid":
        lo, hi = np.array(bound[1], float), np.array(bound[2], float)
        box = T().translate(lo.tolist()).scale((hi - lo).tolist())
        medium = {"type": "heterogeneous", "phase": phase, "albedo": rgb(m["albedo"]), "scale": m["sigma_t"],
                  "sigma_t": {"type": "gridvolume", "filename": os.path.join(out, f"{name}.vol"),
                              "to_world": box, "filter_type": "trilinear"}}
    else:
        medium = {"type": "homogeneous", "phase": phase, "albedo": rgb(m["albedo"]),
                  "sigma_t": m["sigma_t"]}
    if bound[0] == "box":
        lo, hi = np.array(bound[1], float), np.array(bound[2], float)
        shape = {"type": "cube", "to_world": T().translate(((lo + hi) / 2).tolist()).scale(((hi - lo) / 2).tolist())}
    else:
        shape = {"type": "sphere", "center": list(bound[1]), "radius": bound[2]}
    shape["interior"] = medium
    shape["bsdf"] = ({"type": "dielectric", "int_ior": m["glass"], "ext_ior": 1.0} if m["glass"] is not None
                     else {"type": "null"})
    scene["medium_bound"] = shape
    return mi.load_dict(scene)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", nargs="?", default=DEFAULT_OUT)
    ap.add_argument("--spp", type=int, default=4096, help="reference samples per pixel (default 4096)")
    ap.add_argument("--only", default="", help="comma-separated case names")
    ap.add_argument("--scenes-only", action="store_true", help="write the Sahara scene files only")
    ap.add_argument("--variant", default="scalar_rgb")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    todo = cases()
    if args.only:
        todo = {k: todo[k] for k in args.only.split(",")}
    if not args.scenes_only:
        import mitsuba as mi
        mi.set_variant(args.variant)
    for name, case in todo.items():
        if case["medium"]["kind"] == "colour":
            path = os.path.join(args.out, f"{name}.xml")
            with open(path, "w") as f:
                f.write(colour_blob_xml(case, args.out, args.spp, 7))
            if args.scenes_only:
                continue
            image = mi.render(mi.load_file(path))
            mi.util.write_bitmap(os.path.join(args.out, f"{name}.exr"), image)
            print(f"{name}: mean {np.asarray(image).reshape(-1, 3).mean(axis=0)}", flush=True)
            continue
        if case["medium"]["kind"] == "grid":
            _, lo, hi = case["medium"]["bound"]
            write_vol(os.path.join(args.out, f"{name}.vol"), grid_blob(), lo, hi)
        with open(os.path.join(args.out, f"{name}.toml"), "w") as f:
            f.write(sahara_scene(name, case))
        if args.scenes_only:
            continue
        scene = mitsuba_scene(mi, name, case, args.out, args.spp, 7)
        image = mi.render(scene)
        mi.util.write_bitmap(os.path.join(args.out, f"{name}.exr"), image)
        print(f"{name}: mean {np.asarray(image).reshape(-1, 3).mean(axis=0)}", flush=True)


if __name__ == "__main__":
    main()
