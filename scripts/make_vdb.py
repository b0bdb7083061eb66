#!/usr/bin/env python3
"""Writes OpenVDB twins of scenes/assets/blob.vol for Sahara's VDB reader tests.

Needs OpenVDB's Python bindings (Debian: `apt-get install python3-openvdb`, which
installs `pyopenvdb` for /usr/bin/python3) and numpy. The tests read only the
files this writes, so they need neither.

Each file holds one float grid named `density` with the .vol file's values at
the same places: voxel (i, j, k) of the 32^3 grid is the .vol's value (i, j, k),
its centre at lo + (i + 1/2) h with h = (hi - lo) / 32. Voxels of density zero are
left inactive (the background), so the grid's active box is the blob's.

    /usr/bin/python3 scripts/make_vdb.py [--out scenes/assets]

writes blob.vdb (32-bit floats, the library's default compression) and
blob_half.vdb (saved as 16-bit floats), small files the reader refuses
(vdb_vector.vdb: a vector grid; vdb_huge.vdb: a 4096^3 box of tiles;
vdb_rotated.vdb: a rotated map), with --extra DIR a level set there, and with
--fire DIR fireball.vdb there (a density and a temperature grid, the source of
scenes/assets/fireball.nvdb: `nanovdb_convert -z fireball.vdb fireball.nvdb`).
"""
import argparse
import os
import struct

import numpy as np
import pyopenvdb as vdb

HERE = os.path.dirname(os.path.abspath(__file__))
ASSETS = os.path.join(HERE, "..", "scenes", "assets")


def read_vol(path):
    """The density and box of a one-channel .vol file, indexed [z, y, x]."""
    b = open(path, "rb").read()
    magic, version, enc, nx, ny, nz, ch = struct.unpack("<3sBiiiii", b[:24])
    assert magic == b"VOL" and version == 3 and enc == 1 and ch == 1
    lo = struct.unpack("<3f", b[24:36])
    hi = struct.unpack("<3f", b[36:48])
    d = np.frombuffer(b[48:], dtype="<f4").reshape(nz, ny, nx)
    return d, lo, hi


def density_grid(d, lo, hi, name="density"):
    nz, ny, nx = d.shape
    h = (hi[0] - lo[0]) / nx
    assert all(abs((hi[a] - lo[a]) / n - h) < 1e-9 for a, n in ((1, ny), (2, nz)))
    g = vdb.FloatGrid(background=0.0)
    # copyFromArray indexes the array [x, y, z]; values equal to the
    # background stay inactive.
    g.copyFromArray(np.ascontiguousarray(d.transpose(2, 1, 0)), ijk=(0, 0, 0), tolerance=0.0)
    xf = vdb.createLinearTransform(voxelSize=h)
    xf.translate((lo[0] + 0.5 * h, lo[1] + 0.5 * h, lo[2] + 0.5 * h))
    g.transform = xf
    g.name = name
    g.gridClass = vdb.GridClass.FOG_VOLUME
    return g


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=ASSETS)
    ap.add_argument("--extra", default=None, help="also write other kinds of file here")
    ap.add_argument("--fire", default=None, help="also write fireball.vdb (density and temperature) here")
    a = ap.parse_args()
    d, lo, hi = read_vol(os.path.join(ASSETS, "blob.vol"))
    g = density_grid(d, lo, hi)
    vdb.write(os.path.join(a.out, "blob.vdb"), grids=[g])
    h = density_grid(d, lo, hi)
    h.saveFloatAsHalf = True
    vdb.write(os.path.join(a.out, "blob_half.vdb"), grids=[h])
    # Small files the reader must refuse, each for its own reason.
    v = vdb.Vec3SGrid()
    v.name = "velocity"
    v.fill((0, 0, 0), (3, 3, 3), (1.0, 0.0, 0.0))
    vdb.write(os.path.join(a.out, "vdb_vector.vdb"), grids=[v])
    big = vdb.FloatGrid()
    big.name = "density"
    big.fill((0, 0, 0), (4095, 4095, 4095), 1.0)
    vdb.write(os.path.join(a.out, "vdb_huge.vdb"), grids=[big])
    r = vdb.FloatGrid()
    r.name = "density"
    r.fill((0, 0, 0), (3, 3, 3), 1.0)
    xf = vdb.createLinearTransform(voxelSize=0.25)
    xf.rotate(0.5, vdb.Axis.Y)
    r.transform = xf
    vdb.write(os.path.join(a.out, "vdb_rotated.vdb"), grids=[r])
    if a.fire:
        # A fireball for the NanoVDB reader's emission test: the blob at
        # half resolution (16^3) and a temperature grid over the same
        # voxels, 1000 K at its edge to 6000 K at its densest. NanoVDB's
        # converter makes it the asset: nanovdb_convert -z fireball.vdb fireball.nvdb
        os.makedirs(a.fire, exist_ok=True)
        half = d.reshape(16, 2, 16, 2, 16, 2).mean(axis=(1, 3, 5))
        temperature = np.where(half > 0, 1000.0 + 5000.0 * half / half.max(), 0.0)
        fd = density_grid(half, lo, hi)
        ft = density_grid(temperature, lo, hi, name="temperature")
        vdb.write(os.path.join(a.fire, "fireball.vdb"), grids=[fd, ft])
    if a.extra:
        os.makedirs(a.extra, exist_ok=True)
        ls = vdb.createLevelSetSphere(radius=1.0, voxelSize=0.1)
        ls.name = "density"
        vdb.write(os.path.join(a.extra, "level_set.vdb"), grids=[ls])

if __name__ == "__main__":
    main()
