#!/usr/bin/env python3
"""Writes scenes/kit/env_sun.xml and its environment map scenes/kit/env_sun_sky.exr: objects on a
ground under a sky with a small bright sun, in Mitsuba 3's format (Sahara and Mitsuba 3 both read it).

The map is a 512 x 256 lat-long image in Mitsuba's layout (u = 0 looks down -z, u = 1/4 down +x,
row 0 is +y), stored as half floats. The sky is analytic: a gradient from a blue zenith to a pale
horizon, a glow around the sun, and a dim brown ground below the horizon. The sun is a disc of
1.2 degrees radius (about ten texels, their coverage computed by supersampling) at 35 degrees
elevation. Its radiance is set so that on a horizontal surface the sun gives five times the sky's
irradiance, as on a clear day (direct normal about 900 W/m^2, diffuse horizontal about 100 W/m^2):
the sun's texels are then some 10^4 times brighter than the zenith, so nearly all the light comes
from about 0.02 % of the map, the case for sampling the map by its brightness and for MIS
compensation.

The objects: two diffuse spheres, a rough gold sphere (eta and k given as RGB, so that both renderers
read the same numbers) and a diffuse box on a grey ground square reaching almost to the horizon. The
camera looks down on them and sees no sky: the map's light arrives only by reflection. (Sahara looks
a map up by nearest texel and Mitsuba 3 bilinearly; where a pixel is much smaller than a texel, a sky
seen directly would differ pixel by pixel though not on average, an error floor that has nothing to do
with how fast either renderer converges.)

usage: python3 scripts/kit_env_sun.py [OUT_DIR]   (default scenes/kit; needs numpy and OpenEXR)
"""
import math
import os
import sys

import numpy as np

import kit_xml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
W, H = 512, 256
SUN_ELEVATION = math.radians(35.0)
SUN_AZIMUTH = math.radians(-125.0)  # from -z towards +x (Mitsuba's u), so the sun is behind-left
SUN_RADIUS = math.radians(1.2)
SUN_TO_SKY = 5.0  # the sun's horizontal irradiance over the sky's


def direction(u, v):
    """Mitsuba's envmap: texture (u, v) in [0, 1]^2 to a unit direction."""
    phi, theta = 2.0 * math.pi * u, math.pi * v
    s = np.sin(theta)
    return np.stack([s * np.sin(phi), np.cos(theta) * np.ones_like(phi), -s * np.cos(phi)], -1)


def sun_direction():
    c = math.cos(SUN_ELEVATION)
    return np.array([c * math.sin(SUN_AZIMUTH), math.sin(SUN_ELEVATION), -c * math.cos(SUN_AZIMUTH)])


def sky(d):
    """The sky without the sun's disc, per direction (..., 3) -> RGB radiance."""
    y = d[..., 1:2]
    up = np.clip(y, 0.0, 1.0)
    zenith = np.array([0.25, 0.45, 1.0])
    horizon = np.array([0.9, 0.95, 1.05])
    t = up ** 0.5
    blue = horizon * (1.0 - t) + zenith * t
    cos_sun = np.clip(d @ sun_direction(), -1.0, 1.0)
    angle = np.arccos(cos_sun)[..., None]
    glow = (3.0 * np.exp(-angle / 0.12) + 0.4 * np.exp(-angle / 0.6)) * np.array([1.0, 0.9, 0.7])
    above = blue + glow
    ground = np.array([0.16, 0.13, 0.1])
    # a soft horizon line, a fraction of a texel wide
    a = np.clip(y / 0.01 + 0.5, 0.0, 1.0)
    return above * a + ground * (1.0 - a)


def make_map():
    us = (np.arange(W) + 0.5) / W
    vs = (np.arange(H) + 0.5) / H
    u, v = np.meshgrid(us, vs)
    d = direction(u, v)
    img = sky(d)
    # The sun's coverage of each texel, 8 x 8 samples per texel near it.
    n = 8
    sub = (np.arange(n) + 0.5) / n
    cover = np.zeros((H, W))
    s = sun_direction()
    for j in range(n):
        for i in range(n):
            dd = direction((np.arange(W)[None, :] + sub[i]) / W, (np.arange(H)[:, None] + sub[j]) / H)
            cover += (dd @ s > math.cos(SUN_RADIUS)) / (n * n)
    # Solid angle of each texel: (2 pi / W) (pi / H) sin(theta).
    dw = (2.0 * math.pi / W) * (math.pi / H) * np.sin(math.pi * v)
    up = np.clip(d[..., 1], 0.0, None)
    lum = img @ np.array([0.2126, 0.7152, 0.0722])
    e_sky = float(np.sum(lum * up * dw * (1.0 - cover)))
    e_sun_per_radiance = float(np.sum(cover * up * dw))
    sun_l = SUN_TO_SKY * e_sky / e_sun_per_radiance
    sun_rgb = sun_l * np.array([1.0, 0.96, 0.88]) / (np.array([1.0, 0.96, 0.88]) @ [0.2126, 0.7152, 0.0722])
    img = img * (1.0 - cover[..., None]) + sun_rgb * cover[..., None]
    assert img.max() < 65000.0, "the sun's radiance must fit a half float"
    zen = float(sky(np.array([[0.0, 1.0, 0.0]]))[0] @ [0.2126, 0.7152, 0.0722])
    info = (f"sun radiance {sun_l:.0f} ({sun_l / zen:.0f} x the zenith), {int((cover > 0).sum())} "
            f"texels, horizontal irradiance: sky {e_sky:.2f}, sun {SUN_TO_SKY * e_sky:.2f}")
    return img.astype(np.float16), info


def write_exr(path, img):
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    channels = {c: np.ascontiguousarray(img[..., k]) for k, c in enumerate("RGB")}
    tmp = path + ".tmp.exr"
    with OpenEXR.File(header, channels) as f:
        f.write(tmp)
    os.replace(tmp, path)


def scene_lines():
    lines = []
    add = lines.append
    add('<!-- Objects on a ground under a sky with a small bright sun (written by')
    add('     scripts/kit_env_sun.py, with env_sun_sky.exr). Parameters: spp, width, height, max_depth.')
    add('     Render: sahara render scenes/kit/env_sun.xml -D spp=64')
    add('     Mitsuba 3: mitsuba -D spp=64 scenes/kit/env_sun.xml -->')
    kit_xml.scene_start(add, width=320, height=200, max_depth=6, fov=45,
                        origin="0, 2.8, 5.2", target="0, 0.3, 0")
    add('    <emitter type="envmap">')
    add('        <string name="filename" value="env_sun_sky.exr"/>')
    add('    </emitter>')
    add('')
    kit_xml.diffuse(add, [("ground", "0.45, 0.43, 0.4"), ("clay", "0.75, 0.35, 0.2"),
                          ("box", "0.3, 0.5, 0.35")])
    add('    <bsdf type="twosided" id="gold">')
    add('        <bsdf type="roughconductor">')
    add('            <rgb name="eta" value="0.143, 0.374, 1.442"/>')
    add('            <rgb name="k" value="3.983, 2.385, 1.603"/>')
    add('            <string name="distribution" value="ggx"/>')
    add('            <float name="alpha" value="0.15"/>')
    add('        </bsdf>')
    add('    </bsdf>')
    kit_xml.diffuse(add, [("blue", "0.15, 0.25, 0.65")])
    add('')
    add('    <!-- the ground: a 400 x 400 square at y = 0 -->')
    kit_xml.rect(add, "200 0 0 0  0 0 1 0  0 -200 0 0  0 0 0 1", "ground")
    for (x, z, r, mat) in [(-1.3, 0.2, 0.5, "clay"), (0.0, -0.4, 0.6, "gold"), (1.3, 0.3, 0.45, "blue")]:
        add('    <shape type="sphere">')
        add(f'        <point name="center" x="{x:g}" y="{r:g}" z="{z:g}"/>')
        add(f'        <float name="radius" value="{r:g}"/>')
        add(f'        <ref id="{mat}"/>')
        add('    </shape>')
    add('    <shape type="cube">')
    add('        <transform name="to_world">')
    add('            <scale x="0.35" y="0.35" z="0.35"/>')
    add('            <rotate y="1" angle="30"/>')
    add('            <translate x="0.4" y="0.35" z="1.3"/>')
    add('        </transform>')
    add('        <ref id="box"/>')
    add('    </shape>')
    add('</scene>')
    return lines


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "scenes", "kit")
    os.makedirs(out, exist_ok=True)
    img, info = make_map()
    write_exr(os.path.join(out, "env_sun_sky.exr"), img)
    kit_xml.write(os.path.join(out, "env_sun.xml"), scene_lines())
    print(info)


if __name__ == "__main__":
    main()
