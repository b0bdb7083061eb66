#!/usr/bin/env python3
"""Reference images of Sahara's BSDFs, rendered by Mitsuba 3 (an independent renderer).

Each case is one small scene, written twice from one description: as a Mitsuba 3 scene (rendered here at
high spp into a reference EXR) and as a Sahara scene file. The test
`crates/sahara-formats/tests/bsdf_reference.rs` renders the Sahara file and holds it to the reference per
channel and per block (docs/renderer.md, "How the BSDFs are tested").

The scene: a unit sphere of the material on a grey diffuse floor, lit by a small, bright sphere light and a
dim constant environment, seen from slightly above; 64 x 64 pixels, box filter. Both renderers run the same
estimator family (unidirectional path tracing with light sampling and MIS); Mitsuba's `max_depth` D is
Sahara's `max_depth` D - 1 (Mitsuba counts the emitter hit as a bounce).

usage (Mitsuba 3.9.1 from PyPI: `python3 -m venv V && V/bin/pip install mitsuba==3.9.1 numpy OpenEXR`):
    V/bin/python scripts/bsdf_reference.py [--spp N] [--only NAME,...] [--scenes-only] [OUTDIR]
OUTDIR defaults to crates/sahara-formats/tests/bsdf_reference. With --scenes-only, only the Sahara
scene files are written (no Mitsuba needed).
"""
import argparse
import math
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_OUT = os.path.join(ROOT, "crates", "sahara-formats", "tests", "bsdf_reference")

SIZE = 64
MAX_DEPTH = 8                 # Sahara's; Mitsuba renders with MAX_DEPTH + 1
GREY = (0.5, 0.5, 0.5)

# Gold at 650, 550 and 450 nm (Johnson & Christy 1972; Sahara's `metal = "gold"` within 0.01).
GOLD_ETA, GOLD_K = (0.1554, 0.4242, 1.3831), (3.6024, 2.4701, 1.9165)
ALPHAS = (0.001, 0.01, 0.05, 0.1, 0.3, 0.8)
# Cases also written as pbrt-v4 files (held to the same reference image), with their alpha.
PBRT_TOO = {"gold_0p05": 0.05, "gold_0p3": 0.3, "gold_0p8": 0.8}


def conductor_fresnel(mu, n, k):
    """The exact Fresnel reflectance of a conductor of index n + ik at cosine mu (unpolarised)."""
    c2, s2 = mu * mu, 1.0 - mu * mu
    t0 = n * n - k * k - s2
    a2b2 = np.sqrt(t0 * t0 + 4 * n * n * k * k)
    a = np.sqrt(np.maximum(0.5 * (a2b2 + t0), 0.0))
    rs = (a2b2 + c2 - 2 * a * mu) / (a2b2 + c2 + 2 * a * mu)
    rp = rs * (c2 * a2b2 + s2 * s2 - 2 * a * mu * s2) / (c2 * a2b2 + s2 * s2 + 2 * a * mu * s2)
    return 0.5 * (rs + rp)


def index_like_schlick(f0):
    """(n, k) whose exact Fresnel curve is nearest, cosine-weighted, to Schlick's with normal reflectance
    f0, among those with exactly f0 at normal incidence: Mitsuba has no Schlick conductor, so Sahara's
    `color` conductor is compared with this one (the curves differ by under 0.02 here)."""
    mu = np.linspace(1e-3, 1.0, 1000)
    target = f0 + (1 - f0) * (1 - mu) ** 5
    best = None
    # ((n-1)^2 + k^2) / ((n+1)^2 + k^2) = f0, solved for n given k.
    kmax = math.sqrt(((1 + f0) / (1 - f0)) ** 2 - 1)
    for k in np.linspace(0.0, kmax * 0.9999, 4000):
        disc = (1 + f0) ** 2 - (1 - f0) ** 2 * (1 + k * k)
        for n in ((1 + f0 + math.sqrt(max(disc, 0.0))) / (1 - f0), (1 + f0 - math.sqrt(max(disc, 0.0))) / (1 - f0)):
            if n <= 0:
                continue
            err = float(np.sum(mu * (conductor_fresnel(mu, n, k) - target) ** 2))
            if best is None or err < best[0]:
                best = (err, n, k)
    return best[1], best[2]


def cases():
    """name -> (Sahara material table lines, Mitsuba BSDF dict, layout)"""
    rgb = lambda c: {"type": "rgb", "value": [float(x) for x in c]}
    two = lambda b: {"type": "twosided", "bsdf": b}
    out = {"diffuse": (['type = "diffuse"', "albedo = [0.7, 0.45, 0.25]"],
                       two({"type": "diffuse", "reflectance": rgb((0.7, 0.45, 0.25))}), "sphere"),
           "thin_dielectric": (['type = "thin_dielectric"', "ior = 1.5"],
                               {"type": "thindielectric", "int_ior": 1.5, "ext_ior": 1.0}, "sphere")}
    color = (0.95, 0.64, 0.54)
    fit = [index_like_schlick(c) for c in color]
    for a in ALPHAS:
        r = math.sqrt(a)
        tag = f"{a:g}".replace(".", "p")
        # Single scattering, as Mitsuba's (Sahara's multiple-scattering term is tested on its own).
        gold = (['type = "conductor"', f"eta = {list(GOLD_ETA)}", f"k = {list(GOLD_K)}",
                 "multiple_scattering = false", f"roughness = {r!r}"],
                two({"type": "roughconductor", "distribution": "ggx", "alpha": a,
                     "eta": rgb(GOLD_ETA), "k": rgb(GOLD_K)}))
        out[f"gold_{tag}"] = (*gold, "sphere")
        if a in (0.01, 0.05, 0.3):
            out[f"gold_plate_{tag}"] = (*gold, "plate")
        out[f"color_conductor_{tag}"] = (
            ['type = "conductor"', f"color = {list(color)}", f"roughness = {r!r}"],
            two({"type": "roughconductor", "distribution": "ggx", "alpha": a,
                 "eta": rgb([f[0] for f in fit]), "k": rgb([f[1] for f in fit])}),
            "sphere")
        out[f"rough_glass_{tag}"] = (
            ['type = "rough_dielectric"', "ior = 1.5", f"roughness = {r!r}"],
            {"type": "roughdielectric", "distribution": "ggx", "alpha": a, "int_ior": 1.5, "ext_ior": 1.0},
            "sphere")
        if a > 0.1:
            # Rougher, Sahara's metal adds multiple scattering and its coat passes to the base all that
            # its specular lobe does not reflect (white furnace tests); Mitsuba's lose that energy.
            continue
        # Mitsuba's `nonlinear` plastic: the diffuse light the coat reflects back down scatters again,
        # as in Sahara's coated diffuse.
        out[f"coated_{tag}"] = (
            ['type = "coated_diffuse"', "albedo = [0.2, 0.45, 0.7]", "ior = 1.5", f"roughness = {r!r}"],
            two({"type": "roughplastic", "distribution": "ggx", "alpha": a, "int_ior": 1.5, "ext_ior": 1.0,
                 "diffuse_reflectance": rgb((0.2, 0.45, 0.7)), "nonlinear": True}),
            "sphere")
        out[f"metal_{tag}"] = (
            ['type = "metallic_roughness"', "base_color = [0.9, 0.6, 0.3]", "metallic = 1.0",
             f"roughness = {r!r}"],
            two({"type": "principled", "base_color": rgb((0.9, 0.6, 0.3)), "metallic": 1.0, "roughness": r,
                 "specular": 0.5}),
            "sphere")
    # Beckmann, Mitsuba's default distribution for its rough bsdfs: a metal on the sphere and on the plate
    # (the small, bright highlights show the lobe's shape), rough glass, and the coated diffuse.
    for a in (0.01, 0.05, 0.3):
        tag = f"{a:g}".replace(".", "p")
        gold = (['type = "conductor"', f"eta = {list(GOLD_ETA)}", f"k = {list(GOLD_K)}",
                 "multiple_scattering = false", 'distribution = "beckmann"', f"roughness = {math.sqrt(a)!r}"],
                two({"type": "roughconductor", "distribution": "beckmann", "alpha": a,
                     "eta": rgb(GOLD_ETA), "k": rgb(GOLD_K)}))
        out[f"beckmann_gold_{tag}"] = (*gold, "sphere")
        if a == 0.01:
            out[f"beckmann_gold_plate_{tag}"] = (*gold, "plate")
    out["beckmann_rough_glass_0p3"] = (
        ['type = "rough_dielectric"', "ior = 1.5", 'distribution = "beckmann"', f"roughness = {math.sqrt(0.3)!r}"],
        {"type": "roughdielectric", "distribution": "beckmann", "alpha": 0.3, "int_ior": 1.5, "ext_ior": 1.0},
        "sphere")
    out["beckmann_coated_0p05"] = (
        ['type = "coated_diffuse"', "albedo = [0.2, 0.45, 0.7]", "ior = 1.5", 'distribution = "beckmann"',
         f"roughness = {math.sqrt(0.05)!r}"],
        two({"type": "roughplastic", "distribution": "beckmann", "alpha": 0.05, "int_ior": 1.5, "ext_ior": 1.0,
             "diffuse_reflectance": rgb((0.2, 0.45, 0.7)), "nonlinear": True}),
        "sphere")
    return out


def layout(kind):
    """The scene around the sample material, as plain values: camera, objects, lights.

    - `sphere`: a unit sphere of the material on a grey floor, one small sphere light and a dim constant
      environment; every angle of incidence appears on the sphere.
    - `plate`: a flat plate of the material in front of a grey wall, seen at a glancing angle, reflecting
      four sphere lights of equal power and radii 0.03 to 0.9 (radiance 1 to 900): the setting of Veach's
      multiple-importance-sampling scene, where a smooth glossy lobe meets very small, very bright lights.
    """
    if kind == "sphere":
        return {
            "camera": ((0.0, 1.2, 4.6), (0.0, -0.15, 0.0), 32.0),
            "objects": [("sphere", ((0.0, 0.0, 0.0), 1.0), "sample"),
                        ("quad", ((-6.0, -1.0, 6.0), (12.0, 0.0, 0.0), (0.0, 0.0, -12.0)), "grey")],
            "lights": [("sphere", ((2.2, 3.0, 2.0), 0.2), (60.0, 55.0, 50.0))],
            "environment": (0.25, 0.3, 0.4),
        }
    if kind == "plate":
        lights = [("sphere", ((x, 1.2, -2.5), r), tuple(c * (0.03 / r) ** 2 * 900.0 for c in (1.0, 0.9, 0.8)))
                  for x, r in ((-1.8, 0.9), (-0.6, 0.3), (0.6, 0.1), (1.8, 0.03))]
        return {
            "camera": ((0.0, 1.0, 4.0), (0.0, 0.0, 0.0), 40.0),
            "objects": [("quad", ((-2.5, 0.0, 1.2), (5.0, 0.0, 0.0), (0.0, 0.0, -2.4)), "sample"),
                        ("quad", ((-8.0, -1.0, -4.0), (16.0, 0.0, 0.0), (0.0, 10.0, 0.0)), "grey"),
                        ("quad", ((-8.0, -1.0, 8.0), (16.0, 0.0, 0.0), (0.0, 0.0, -12.0)), "grey")],
            "lights": lights,
            "environment": (0.02, 0.02, 0.03),
        }
    raise ValueError(kind)


def fmt(t):
    return "[" + ", ".join(f"{float(x)!r}" for x in t) + "]"


def sahara_scene(name, material, kind):
    """The Sahara scene file of one case."""
    lay = layout(kind)
    eye, target, vfov = lay["camera"]
    lines = [
        f"# BSDF reference scene '{name}': written by scripts/bsdf_reference.py; Mitsuba 3 rendered {name}.exr",
        "[camera]", f"eye = {fmt(eye)}", f"target = {fmt(target)}", f"vfov = {vfov!r}", "",
        "[film]", f"width = {SIZE}", f"height = {SIZE}", "",
        "[filter]", 'name = "box"', "",
        "[integrator]", 'name = "path"', f"max_depth = {MAX_DEPTH}", "",
        "[[material]]", 'name = "sample"', *material, "",
        "[[material]]", 'name = "grey"', 'type = "diffuse"', f"albedo = {fmt(GREY)}", "",
    ]
    for shape, geo, mat in lay["objects"]:
        lines += ["[[object]]", f'type = "{shape}"']
        if shape == "sphere":
            lines += [f"center = {fmt(geo[0])}", f"radius = {geo[1]!r}"]
        else:
            lines += [f"corner = {fmt(geo[0])}", f"edge_u = {fmt(geo[1])}", f"edge_v = {fmt(geo[2])}"]
        lines += [f'material = "{mat}"', ""]
    for shape, (center, radius), radiance in lay["lights"]:
        lines += ["[[light]]", 'type = "area"', 'shape = "sphere"', f"center = {fmt(center)}",
                  f"radius = {radius!r}", f"radiance = {fmt(radiance)}", ""]
    lines += ["[[light]]", 'type = "environment"', f"radiance = {fmt(lay['environment'])}", ""]
    return "\n".join(lines)


def pbrt_scene(name, alpha):
    """The `sphere` layout with the gold conductor as a pbrt-v4 file (its `remaproughness false` gives
    alpha itself): pbrt's conductor is read as the single-scattering one, as pbrt-v4 renders it."""
    lay = layout("sphere")
    eye, target, vfov = lay["camera"]
    p = lambda t: " ".join(f"{float(x)!r}" for x in t)
    (center, radius), light = lay["objects"][0][1], lay["lights"][0]
    corner, eu, ev = (np.array(g, float) for g in lay["objects"][1][1])
    quad = [corner, corner + eu, corner + eu + ev, corner + ev]
    lines = [
        f"# BSDF reference scene '{name}' as pbrt-v4: written by scripts/bsdf_reference.py",
        "# pbrt's camera space is left-handed: mirrored so that the image is the Mitsuba reference's.",
        "Scale -1 1 1",
        f"LookAt {p(eye)}  {p(target)}  0 1 0",
        f'Camera "perspective" "float fov" [ {vfov!r} ]',
        f'Film "rgb" "integer xresolution" [ {SIZE} ] "integer yresolution" [ {SIZE} ]',
        'PixelFilter "box"',
        f'Integrator "path" "integer maxdepth" [ {MAX_DEPTH} ]',
        "WorldBegin",
        f'LightSource "infinite" "rgb L" [ {p(lay["environment"])} ]',
        "AttributeBegin",
        f'  Material "conductor" "rgb eta" [ {p(GOLD_ETA)} ] "rgb k" [ {p(GOLD_K)} ]',
        f'    "float roughness" [ {alpha!r} ] "bool remaproughness" false',
        f"  Translate {p(center)}",
        f'  Shape "sphere" "float radius" [ {radius!r} ]',
        "AttributeEnd",
        "AttributeBegin",
        f'  Material "diffuse" "rgb reflectance" [ {p(GREY)} ]',
        f'  Shape "trianglemesh" "point3 P" [ {" ".join(p(v) for v in quad)} ] "integer indices" [ 0 1 2 0 2 3 ]',
        "AttributeEnd",
        "AttributeBegin",
        f'  AreaLightSource "diffuse" "rgb L" [ {p(light[2])} ]',
        '  Material "diffuse" "rgb reflectance" [ 0 0 0 ]',
        f"  Translate {p(light[1][0])}",
        f'  Shape "sphere" "float radius" [ {light[1][1]!r} ]',
        "AttributeEnd",
        "",
    ]
    return "\n".join(lines)


def mitsuba_scene(mi, bsdf, kind, spp, seed):
    lay = layout(kind)
    eye, target, vfov = lay["camera"]
    rgb = lambda c: {"type": "rgb", "value": list(c)}
    T = mi.ScalarTransform4f
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": MAX_DEPTH + 1, "rr_depth": 1000},
        "sensor": {
            "type": "perspective", "fov_axis": "y", "fov": vfov, "near_clip": 1e-3,
            "to_world": T().look_at(origin=eye, target=target, up=(0, 1, 0)),
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
            "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE, "pixel_format": "rgb",
                     "rfilter": {"type": "box"}},
        },
        "env": {"type": "constant", "radiance": rgb(lay["environment"])},
    }
    materials = {"sample": bsdf, "grey": {"type": "diffuse", "reflectance": rgb(GREY)}}
    for i, (shape, geo, mat) in enumerate(lay["objects"]):
        if shape == "sphere":
            s = {"type": "sphere", "center": list(geo[0]), "radius": geo[1]}
        else:
            # Mitsuba's rectangle spans [-1, 1]^2 in z = 0, normal +z: map it onto corner + s u + t v,
            # normal along u x v (Sahara's front face).
            c, u, v = (np.array(g, float) for g in geo)
            n = np.cross(u, v)
            m = np.eye(4)
            m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n / np.linalg.norm(n), c + (u + v) / 2
            s = {"type": "rectangle", "to_world": T(m.tolist())}
        # Sahara's reflectors are two-sided; so are the reference's (cases() wraps its reflectors).
        s["bsdf"] = materials[mat] if mat == "sample" else {"type": "twosided", "bsdf": materials[mat]}
        scene[f"object{i}"] = s
    for i, (shape, (center, radius), radiance) in enumerate(lay["lights"]):
        scene[f"light{i}"] = {"type": "sphere", "center": list(center), "radius": radius,
                              "bsdf": {"type": "diffuse", "reflectance": rgb((0, 0, 0))},
                              "emitter": {"type": "area", "radiance": rgb(radiance)}}
    return mi.load_dict(scene)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", nargs="?", default=DEFAULT_OUT)
    ap.add_argument("--spp", type=int, default=8192, help="reference samples per pixel (default 8192)")
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
    for name, (material, bsdf, kind) in todo.items():
        with open(os.path.join(args.out, f"{name}.toml"), "w") as f:
            f.write(sahara_scene(name, material, kind))
        if name in PBRT_TOO:
            with open(os.path.join(args.out, f"{name}.pbrt"), "w") as f:
                f.write(pbrt_scene(name, PBRT_TOO[name]))
        if args.scenes_only:
            continue
        # Two halves with different seeds: their difference tells the reference's own noise.
        halves = [np.array(mi.render(mitsuba_scene(mi, bsdf, kind, args.spp // 2, seed), seed=seed))
                  for seed in (1, 2)]
        img = 0.5 * (halves[0] + halves[1])
        # Half floats: three significant digits are plenty for tolerances of a percent or more.
        bmp = mi.Bitmap(img.astype(np.float16), pixel_format=mi.Bitmap.PixelFormat.RGB)
        bmp.write(os.path.join(args.out, f"{name}.exr"))
        noise = float(np.sqrt(np.mean((halves[0] - halves[1]) ** 2) / 4))
        print(f"{name}: mean {img.reshape(-1, 3).mean(0).round(4).tolist()}, reference rms noise {noise:.5f}",
              flush=True)


if __name__ == "__main__":
    sys.exit(main())
