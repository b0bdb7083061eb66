"""sahara.trimesh.RayMeshIntersector against trimesh's own intersector
(the pure-numpy one, trimesh's default without embreex) on trimesh's
primitives."""

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")
from trimesh.ray.ray_triangle import RayMeshIntersector as TrimeshIntersector  # noqa: E402

import sahara.trimesh  # noqa: E402


def primitives():
    yield "box", trimesh.creation.box(extents=(1.0, 2.0, 0.5))
    yield "icosphere", trimesh.creation.icosphere(subdivisions=3)
    yield "capsule", trimesh.creation.capsule(height=1.0, radius=0.4, count=[16, 16])
    yield "cylinder", trimesh.creation.cylinder(radius=0.5, height=1.5, sections=24)
    yield "torus", trimesh.creation.torus(major_radius=1.0, minor_radius=0.3, major_sections=24, minor_sections=12)


def rays(mesh, n=2000, seed=0):
    """Rays from around the mesh towards random points of its box (no ray
    along an axis, so none runs exactly through an edge by construction)."""
    rng = np.random.default_rng(seed)
    lo, hi = mesh.bounds
    size = hi - lo
    o = lo - size + rng.random((n, 3)) * 3 * size
    target = lo + rng.random((n, 3)) * size
    return o, target - o


@pytest.mark.parametrize("name, mesh", list(primitives()))
def test_first_hits_and_any_hits_match_trimesh(name, mesh):
    o, d = rays(mesh)
    ours = sahara.trimesh.RayMeshIntersector(mesh)
    theirs = TrimeshIntersector(mesh)
    first = ours.intersects_first(o, d)
    assert first.dtype == np.int64 and first.shape == (len(o),)
    want = theirs.intersects_first(o, d)
    hit = want >= 0
    assert hit.sum() > 300, name
    np.testing.assert_array_equal(ours.intersects_any(o, d), theirs.intersects_any(o, d))
    # The same triangle, or (a ray through an edge) one as near.
    same = first == want
    assert same.mean() > 0.995, name
    loc_ours, ray_ours, _ = ours.intersects_location(o, d, multiple_hits=False)
    loc_theirs, ray_theirs, _ = theirs.intersects_location(o, d, multiple_hits=False)
    np.testing.assert_array_equal(np.sort(ray_ours), np.sort(ray_theirs))
    a = loc_ours[np.argsort(ray_ours, kind="stable")]
    b = loc_theirs[np.argsort(ray_theirs, kind="stable")]
    np.testing.assert_allclose(a, b, atol=1e-5 * mesh.scale)


@pytest.mark.parametrize("name, mesh", list(primitives()))
def test_multiple_hits_match_trimesh(name, mesh):
    o, d = rays(mesh, seed=1)
    ours = sahara.trimesh.RayMeshIntersector(mesh)
    tri, ray, loc = ours.intersects_id(o, d, return_locations=True, multiple_hits=True)
    want_tri, want_ray = TrimeshIntersector(mesh).intersects_id(o, d, multiple_hits=True)
    # trimesh's numpy intersector lists hits behind the origin's plane only
    # in front of the ray, as Sahara: the same (ray, triangle) pairs.
    ours_pairs = set(zip(ray.tolist(), tri.tolist()))
    theirs_pairs = set(zip(want_ray.tolist(), want_tri.tolist()))
    differ = ours_pairs ^ theirs_pairs
    assert len(differ) <= 0.002 * len(theirs_pairs) + 2, (name, sorted(differ)[:10])
    # Ordered by ray, then distance; the locations lie on the rays.
    assert (np.diff(ray) >= 0).all()
    t = np.einsum("ij,ij->i", loc - o[ray], d[ray]) / np.einsum("ij,ij->i", d[ray], d[ray])
    same_ray = np.diff(ray) == 0
    assert (np.diff(t)[same_ray] >= 0).all()
    # A closed mesh is crossed an even number of times by a ray from outside it.
    counts = np.bincount(ray, minlength=len(o))
    outside = ~mesh.contains(o) if mesh.is_watertight else np.ones(len(o), bool)
    if mesh.is_watertight:
        assert (counts[outside] % 2 == 0).mean() > 0.995, name
    capped_tri, capped_ray = ours.intersects_id(o, d, multiple_hits=True, max_hits=1)
    np.testing.assert_array_equal(capped_ray, np.unique(ray))


@pytest.mark.parametrize("name, mesh", list(primitives()))
def test_contains_points_matches_trimesh(name, mesh):
    rng = np.random.default_rng(5)
    lo, hi = mesh.bounds
    p = lo - 0.1 + rng.random((3000, 3)) * (hi - lo + 0.2)
    ours = sahara.trimesh.RayMeshIntersector(mesh).contains_points(p)
    want = TrimeshIntersector(mesh).contains_points(p)
    # Points within a hair of the surface may go either way.
    _, distance, _ = trimesh.proximity.closest_point(mesh, p)
    clear = distance > 1e-6
    np.testing.assert_array_equal(ours[clear], want[clear])
    assert ours.sum() > 100
    # RayScene.contains, the native parity test, agrees on clear points.
    native = sahara.trimesh.RayMeshIntersector(mesh).scene.contains(p)
    np.testing.assert_array_equal(native[clear], want[clear])


def test_it_replaces_mesh_ray_and_follows_mesh_changes():
    mesh = trimesh.creation.icosphere(subdivisions=2)
    mesh.ray = sahara.trimesh.RayMeshIntersector(mesh)
    assert mesh.contains([[0, 0, 0], [2, 0, 0]]).tolist() == [True, False]
    mesh.apply_translation([5, 0, 0])
    assert mesh.contains([[0, 0, 0], [5, 0, 0]]).tolist() == [False, True]
    first = mesh.ray.intersects_first([[0, 0, 0]], [[1, 0, 0]])
    assert first[0] >= 0
    with pytest.raises(ValueError, match="don't match"):
        mesh.ray.intersects_first([[0, 0, 0]], [[1, 0, 0], [0, 1, 0]])
