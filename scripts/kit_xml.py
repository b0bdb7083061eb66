"""Pieces of the kit's scene files in Mitsuba 3's format (Sahara and Mitsuba 3 both read them),
shared by the scripts that write them (kit_door_ajar.py, kit_hall_lamps.py, kit_env_sun.py): the
scene's parameters, path tracer and camera; diffuse materials; rectangles; the atomic write.

Every function appends lines to a list through `add` (its `append`), so a script writes its scene
top to bottom in the file's order.
"""
import os


def scene_start(add, *, width, height, max_depth, fov, origin, target):
    """The scene element, its parameters (spp, width, height, max_depth, with these defaults and 64
    samples), the path tracer, and a perspective camera of horizontal field of view `fov` degrees
    looking from `origin` at `target` (strings "x, y, z"), box filter, independent sampler."""
    add('<scene version="3.0.0">')
    add('    <default name="spp" value="64"/>')
    add(f'    <default name="width" value="{width}"/>')
    add(f'    <default name="height" value="{height}"/>')
    add(f'    <default name="max_depth" value="{max_depth}"/>')
    add('')
    add('    <integrator type="path">')
    add('        <integer name="max_depth" value="$max_depth"/>')
    add('    </integrator>')
    add('')
    add('    <sensor type="perspective">')
    add(f'        <float name="fov" value="{fov}"/>')
    add('        <string name="fov_axis" value="x"/>')
    add('        <transform name="to_world">')
    add(f'            <lookat origin="{origin}" target="{target}" up="0, 1, 0"/>')
    add('        </transform>')
    add('        <sampler type="independent">')
    add('            <integer name="sample_count" value="$spp"/>')
    add('        </sampler>')
    add('        <film type="hdrfilm">')
    add('            <integer name="width" value="$width"/>')
    add('            <integer name="height" value="$height"/>')
    add('            <rfilter type="box"/>')
    add('        </film>')
    add('    </sensor>')
    add('')


def diffuse(add, materials):
    """Two-sided diffuse materials: `materials` is a list of (id, reflectance "r, g, b")."""
    for name, rgb in materials:
        add(f'    <bsdf type="twosided" id="{name}">')
        add(f'        <bsdf type="diffuse"><rgb name="reflectance" value="{rgb}"/></bsdf>')
        add('    </bsdf>')


def rect(add, matrix, mat, radiance=None):
    """A rectangle: [-1, 1]^2 in z = 0 placed by the 4x4 row-major `matrix` (a string of 16
    numbers), of material `mat`, emitting `radiance` ("r, g, b") if given."""
    add('    <shape type="rectangle">')
    add(f'        <transform name="to_world"><matrix value="{matrix}"/></transform>')
    add(f'        <ref id="{mat}"/>')
    if radiance:
        add('        <emitter type="area">')
        add(f'            <rgb name="radiance" value="{radiance}"/>')
        add('        </emitter>')
    add('    </shape>')


def write(path, lines):
    """The lines to `path` (its folder made if need be), through a temporary file renamed over it,
    so a failed run never leaves half a scene."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, path)
