"""The Mitsuba comparison kit's scenes (../shared/compare/mitsuba/scenes.py), plus `cornell_quads`: Mitsuba's
own `mi.cornell_box()` as a box of quads with a quad light.

usage: scenes.py OUTDIR        (run by scripts/mitsuba_compare/compare.sh in place of the kit's scenes.py)

`cornell_quads` is read from `mi.cornell_box()` at run time: its five walls and its light are rectangles, its two
boxes cubes, so the scene is 18 quads (36 triangles), one of them the light. Each rectangle's `to_world` maps
[-1, 1]^2 onto the quad, so corner = M (-1, -1, 0), edges = M (2, 0, 0) and M (0, 2, 0), front along
edge_u x edge_v as Mitsuba's normal; a cube is its six faces the same way. Everything else follows the kit's
conventions (README.md there): Mitsuba max_depth 8 as in `cornell_box()` (Sahara 7), Russian roulette off in both,
a black light surface (`cornell_box()` gives the light the white BSDF; the kit's area lights are black in both
renderers), independent sampler, box filter, 256 x 256 as in `cornell_box()`.
"""
import hashlib, json, os, sys

import numpy as np

from kit_scenes import SCENES, write  # the kit's scenes.py, linked beside this file by compare.sh


def cornell_quads():
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    box = mi.cornell_box()

    def matrix(t):
        return np.array(t.matrix, dtype=float)

    def quad(m, face=np.eye(4)):
        m = m @ face
        p = lambda x, y: (m @ np.array([x, y, 0.0, 1.0]))[:3]
        corner = p(-1, -1)
        return {"corner": [float(c) for c in corner], "edge_u": [float(c) for c in p(1, -1) - corner],
                "edge_v": [float(c) for c in p(-1, 1) - corner]}

    def rot(axis, deg):
        """4x4 rotation about a coordinate axis"""
        c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
        r = np.eye(4)
        i, j = [(1, 2), (2, 0), (0, 1)][axis]
        r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
        return r

    def shift(v):
        t = np.eye(4)
        t[:3, 3] = v
        return t

    # the six faces of [-1, 1]^3, each a rectangle whose normal points out
    cube_faces = [shift(n) @ r for n, r in [((0, 0, 1), np.eye(4)), ((0, 0, -1), rot(0, 180)),
                                             ((1, 0, 0), rot(1, 90)), ((-1, 0, 0), rot(1, -90)),
                                             ((0, 1, 0), rot(0, -90)), ((0, -1, 0), rot(0, 90))]]
    s = box["sensor"]
    cam_m = matrix(s["to_world"])
    eye = cam_m[:3, 3]
    assert s["fov_axis"] == "smaller" and s["film"]["width"] == s["film"]["height"]
    sc = {"film": [s["film"]["width"], s["film"]["height"]], "max_depth": box["integrator"]["max_depth"],
          "camera": {"eye": list(eye), "target": list(eye + cam_m[:3, 2]), "up": list(cam_m[:3, 1]),
                     "vfov": s["fov"]},
          "materials": {}, "objects": [], "lights": []}
    for name, v in box.items():
        if isinstance(v, dict) and v.get("type") == "diffuse":
            sc["materials"][name] = {"type": "diffuse", "albedo": [float(c) for c in v["reflectance"]["value"]]}
    for name, v in box.items():
        if not isinstance(v, dict) or v.get("type") not in ("rectangle", "cube"):
            continue
        m = matrix(v["to_world"])
        if "emitter" in v:
            sc["lights"].append({"type": "area", **quad(m), "radiance": [float(c) for c in v["emitter"]["radiance"]["value"]]})
            continue
        faces = cube_faces if v["type"] == "cube" else [np.eye(4)]
        for f in faces:
            sc["objects"].append({"type": "quad", **quad(m, f), "material": v["bsdf"]["id"]})
    return sc


if __name__ == "__main__":
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    scenes = dict(SCENES)
    scenes["cornell_quads"] = cornell_quads()
    info = {}
    for name, sc in scenes.items():
        xml, toml, notes = write(name, sc, out)
        key = hashlib.sha256((json.dumps(sc, sort_keys=True) + open(__file__).read()).encode()).hexdigest()[:12]
        info[name] = {"xml": xml, "toml": toml, "key": key, "notes": notes}
        print(f"{name}: {os.path.basename(xml)}, {os.path.basename(toml)}" + "".join(f"\n  {n}" for n in notes))
    json.dump(info, open(os.path.join(out, "scenes.json"), "w"), indent=1)
