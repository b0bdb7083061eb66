"""Shared fixtures: small meshes made here, the `sahara` command line (for
agreement with the Rust queries and renders), the shared benchmark meshes."""

import os
import pathlib
import shutil

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


def icosphere(subdivisions=2, radius=1.0, center=(0.0, 0.0, 0.0)):
    """A closed, consistently wound sphere of 20 * 4**subdivisions triangles."""
    t = (1.0 + 5.0**0.5) / 2.0
    v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
         [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    v = [np.array(p, dtype=np.float64) / np.linalg.norm(p) for p in v]
    for _ in range(subdivisions):
        cache, nf = {}, []

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                p = v[a] + v[b]
                v.append(p / np.linalg.norm(p))
                cache[key] = len(v) - 1
            return cache[key]

        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        f = nf
    return np.array(v) * radius + np.array(center), np.array(f, dtype=np.int64)


def write_obj(path, vertices, faces):
    with open(path, "w") as out:
        out.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in np.asarray(vertices, np.float32).tolist())
        out.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces.tolist())


@pytest.fixture(scope="session")
def sahara_bin():
    """The command line: SAHARA_BIN, else target/release/sahara. Where
    SAHARA_BIN is set (CI) a missing binary fails; else the test skips."""
    given = os.environ.get("SAHARA_BIN")
    path = pathlib.Path(given) if given else ROOT / "target" / "release" / "sahara"
    if not path.is_file():
        if given:
            pytest.fail(f"SAHARA_BIN={given}: no such file")
        found = shutil.which("sahara")
        if not found:
            pytest.skip("no sahara binary: build it with `cargo build --release` or set SAHARA_BIN")
        path = pathlib.Path(found)
    return str(path)


@pytest.fixture(scope="session")
def shared_scenes():
    path = pathlib.Path(os.environ.get("SAHARA_SCENES", ROOT.parent / "shared" / "scenes"))
    if not (path / "bunny" / "bunny.ply").is_file():
        pytest.skip(f"the shared benchmark meshes are not in {path} (set SAHARA_SCENES)")
    return path
