"""RayScene: shapes and dtypes in and out, refusals, and agreement with the
Rust queries (through the command line's ray and hit files)."""

import subprocess
import threading

import numpy as np
import pytest

import sahara
from conftest import icosphere, write_obj

SQUARE_V = np.array([[-1, -1, 5], [1, -1, 5], [1, 1, 5], [-1, 1, 5]], dtype=np.float32)
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)


def random_rays(n, seed=1, spread=3.0):
    rng = np.random.default_rng(seed)
    o = (rng.random((n, 3)) - 0.5) * 2 * spread
    d = rng.normal(size=(n, 3))
    return o.astype(np.float32), d.astype(np.float32)


def test_cast_rays_returns_arrays_of_each_ray():
    s = sahara.RayScene(SQUARE_V, SQUARE_F)
    out = s.cast_rays(np.array([[0.5, -0.5, 0], [5, 5, 0]], np.float32), np.array([0, 0, 1], np.float32))
    assert set(out) == {"t", "triangle", "mesh", "u", "v", "normal"}
    assert out["t"].dtype == np.float32 and out["t"].shape == (2,)
    assert out["triangle"].dtype == np.int32 and out["mesh"].dtype == np.int32
    assert out["normal"].shape == (2, 3) and out["normal"].dtype == np.float32
    assert out["t"][0] == 5.0 and out["triangle"][0] == 0 and out["mesh"][0] == 0
    assert (out["u"][0], out["v"][0]) == (0.5, 0.25)
    assert out["normal"][0].tolist() == [0.0, 0.0, 1.0]
    # A miss: inf, -1, zeros.
    assert out["t"][1] == np.inf and out["triangle"][1] == -1 and out["mesh"][1] == -1
    assert out["normal"][1].tolist() == [0.0, 0.0, 0.0]


def test_every_float_layout_gives_the_same_answers():
    v, f = icosphere(2)
    s = sahara.RayScene(v, f)
    o, d = random_rays(3000, spread=1.5)
    want = s.cast_rays(o, d)
    assert (want["triangle"] >= 0).sum() > 500
    wide = np.zeros((3000, 6), np.float32)
    wide[:, ::2] = o  # strided rows, read in place
    for oo, dd in [(o.astype(np.float64), d.astype(np.float64)), (wide[:, ::2], d),
                   (np.asfortranarray(o), d.tolist())]:
        got = s.cast_rays(oo, dd)
        for k in want:
            np.testing.assert_array_equal(got[k], want[k], err_msg=k)
    # float32 and float64 vertices, int32/int64/uint32 faces build the same tree.
    for vv, ff in [(v.astype(np.float32), f.astype(np.uint32)), (v, f.astype(np.int32))]:
        got = sahara.RayScene(vv, ff).cast_rays(o, d)
        np.testing.assert_array_equal(got["t"], want["t"])


def test_one_origin_or_direction_is_broadcast_and_intervals_apply():
    s = sahara.RayScene(SQUARE_V, SQUARE_F)
    d = np.array([[0.1, 0, 1], [0, 0.1, 1], [0, 0, -1]], np.float32)
    out = s.cast_rays([0, 0, 0], d)
    assert out["triangle"].tolist()[:2] != [-1, -1] and out["triangle"][2] == -1
    # (tmin, tmax]: a hit at exactly tmax counts, at tmin not.
    assert s.occluded([0, 0, 0], [0, 0, 1], tmax=5.0).tolist() == [True]
    assert s.occluded([0, 0, 0], [0, 0, 1], tmax=4.999).tolist() == [False]
    assert s.occluded([0, 0, 0], [0, 0, 1], tmin=5.0).tolist() == [False]
    tmax = np.array([4.0, 6.0, 6.0])
    assert s.occluded([0, 0, 0], d, tmax=tmax).tolist() == [False, True, False]
    # Degenerate rays hit nothing rather than fail.
    bad = s.cast_rays([[0, 0, 0], [np.nan, 0, 0], [0, 0, 0]], [[0, 0, 0], [0, 0, 1], [0, 0, 1]],
                      tmin=np.array([0, 0, -1.0]))
    assert bad["triangle"].tolist() == [-1, -1, -1]


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F + 2), "faces: row 0 refers to vertex 4, out of range for 4 vertices"),
        (lambda: sahara.RayScene(SQUARE_V, -SQUARE_F), "faces: row 0 refers to vertex -1"),
        (lambda: sahara.RayScene(SQUARE_V * np.nan, SQUARE_F), "vertices: row 0 holds a NaN"),
        (lambda: sahara.RayScene(np.array([[0, 0, 1e300]]), np.zeros((0, 3), int)), "vertices: row 0 holds a NaN or infinite"),
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F.astype(float)), "faces: expected an array of shape (M, 3) of integers"),
        (lambda: sahara.RayScene(SQUARE_V[:, :2], SQUARE_F), "vertices: expected an array of shape (N, 3) of numbers, got shape (4, 2)"),
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F[:, :2]), "faces: expected an array of shape (M, 3)"),
        (lambda: sahara.RayScene(SQUARE_V.astype(str), SQUARE_F), "vertices: expected"),
        (lambda: sahara.RayScene(SQUARE_V), "give both vertices and faces"),
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F, builder="bvh"), "builder: unknown builder 'bvh'"),
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F, accel="octree"), "accel: unknown structure 'octree'"),
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F, accel="kd", builder="spatial"), "builder: unknown builder 'spatial'"),
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F).cast_rays(np.zeros((3, 3)), np.zeros((2, 3))), "origins and directions: 3 and 2 rows"),
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F).cast_rays(np.zeros((3, 4)), np.zeros((3, 3))), "origins: expected an array of shape (N, 3) or (3,)"),
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F).occluded(np.zeros((3, 3)), [0, 0, 1], tmax=np.ones(2)), "tmax: expected a number or an array of shape (3,)"),
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F).contains(np.zeros((2, 3)), samples=0), "samples: expected 1..=7"),
        # A count out of range is a ValueError naming it, not the
        # conversion's OverflowError.
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F).all_hits([0, 0, 0], [0, 0, 1], max_hits=-1), "max_hits must be at least 0, not -1"),
        (lambda: sahara.RayScene(SQUARE_V, SQUARE_F).all_hits([0, 0, 0], [0, 0, 1], max_hits=2**70), "max_hits must be at most"),
    ],
)
def test_bad_inputs_are_value_errors_that_say_what(make, message):
    with pytest.raises(ValueError) as e:
        make()
    assert message in str(e.value)


def test_out_reuses_the_arrays_of_an_earlier_call():
    v, f = icosphere(2)
    s = sahara.RayScene(v, f)
    o, d = random_rays(1000, spread=1.5)
    o2, d2 = random_rays(1000, seed=2, spread=1.5)
    out = s.cast_rays(o, d)
    arrays = {k: a for k, a in out.items()}
    again = s.cast_rays(o2, d2, out=out)
    assert again is out and all(out[k] is arrays[k] for k in arrays)
    want = s.cast_rays(o2, d2)
    for k in want:
        np.testing.assert_array_equal(out[k], want[k], err_msg=k)


def out_with(**changes):
    out = sahara.RayScene(SQUARE_V, SQUARE_F).cast_rays(np.zeros((4, 3)), [0, 0, 1])
    for k, a in changes.items():
        out[k] = a(out[k]) if callable(a) else a
    return out


def read_only(a):
    a.flags.writeable = False
    return a


@pytest.mark.parametrize(
    "out, error, message",
    [
        ([], TypeError, "out: expected the dict of arrays cast_rays returned"),
        (out_with(t=None), ValueError, "out['t']: expected a float32 array"),
        (out_with(u=lambda a: a.astype(np.float64)), ValueError, "out['u']: expected a float32 array"),
        (out_with(triangle=lambda a: a[:3]), ValueError, "out['triangle']: expected shape (4,) (the rays of this call), got (3,)"),
        (out_with(normal=lambda a: np.zeros((4, 2), np.float32)), ValueError, "out['normal']: expected shape (4, 3) (the rays of this call), got (4, 2)"),
        (out_with(normal=np.asfortranarray), ValueError, "out['normal']: expected a C-contiguous array"),
        (out_with(v=lambda a: np.zeros(8, np.float32)[::2]), ValueError, "out['v']: expected a C-contiguous array"),
        (out_with(mesh=read_only), ValueError, "out['mesh']: cannot be written"),
        (out_with(v=lambda a: a, u=None), ValueError, "out['u']: expected a float32 array"),
    ],
)
def test_bad_out_arrays_are_refused(out, error, message):
    s = sahara.RayScene(SQUARE_V, SQUARE_F)
    with pytest.raises(error) as e:
        s.cast_rays(np.zeros((4, 3), np.float32), np.array([0, 0, 1], np.float32), out=out)
    assert message in str(e.value)


def test_out_may_not_share_memory_with_the_rays_or_itself():
    s = sahara.RayScene(SQUARE_V, SQUARE_F)
    o = np.zeros((4, 3), np.float32)
    out = s.cast_rays(o, [0, 0, 1])
    with pytest.raises(ValueError, match="out\\['normal'\\]: cannot be written"):
        s.cast_rays(out["normal"], [0, 0, 1], out=out)
    out["u"] = out["v"]
    with pytest.raises(ValueError, match="out\\['v'\\]: cannot be written"):
        s.cast_rays(o, [0, 0, 1], out=out)


def test_meshes_have_ids_and_triangles_count_within_their_mesh():
    s = sahara.RayScene()
    assert s.mesh_count == 0 and s.cast_rays([0, 0, 0], [0, 0, 1])["mesh"].tolist() == [-1]
    a = s.add_mesh(SQUARE_V, SQUARE_F)
    b = s.add_mesh(SQUARE_V + [0, 0, 5], SQUARE_F[::-1])
    assert (a, b, s.mesh_count, s.triangle_count) == (0, 1, 2, 4)
    out = s.cast_rays([[0.5, -0.5, 0], [0.5, -0.5, 7]], [0, 0, 1])
    assert out["mesh"].tolist() == [0, 1]
    # The second mesh's faces are reversed: its first face is the square's second.
    assert out["triangle"].tolist() == [0, 1]
    assert s.count_intersections([0.5, -0.5, 0], [0, 0, 1]).tolist() == [2]
    hits = s.all_hits([[0.5, -0.5, 0], [0, 0, 20]], [0, 0, 1])
    assert hits["ray"].tolist() == [0, 0] and hits["mesh"].tolist() == [0, 1]
    assert hits["t"].tolist() == [5.0, 10.0]


def test_every_hit_is_found_once_and_the_first_is_the_closest():
    v, f = icosphere(3)
    s = sahara.RayScene(np.vstack([v, v * 0.5]), np.vstack([f, f + len(v)]))
    o, d = random_rays(2000, spread=0.3)
    first = s.cast_rays(o, d)
    counts = s.count_intersections(o, d)
    hits = s.all_hits(o, d)
    np.testing.assert_array_equal(np.bincount(hits["ray"], minlength=len(o)), counts)
    starts = np.searchsorted(hits["ray"], np.arange(len(o)))
    hit = counts > 0
    np.testing.assert_array_equal(hits["t"][starts[hit]], first["t"][hit])
    np.testing.assert_array_equal(hits["triangle"][starts[hit]], first["triangle"][hit])
    # From inside both spheres a ray crosses each once; from between them,
    # the outer one once and the inner one twice or not at all.
    r = np.linalg.norm(o, axis=1)
    assert (counts[r < 0.49] == 2).all() and (counts[(r > 0.51) & (r < 0.99)] % 2 == 1).all()
    capped = s.all_hits(o, d, max_hits=1)
    np.testing.assert_array_equal(capped["ray"], np.flatnonzero(hit))


def test_contains_by_parity_on_a_closed_sphere():
    v, f = icosphere(3, radius=2.0, center=(1, 2, 3))
    s = sahara.RayScene(v, f)
    rng = np.random.default_rng(3)
    p = rng.uniform(-2, 2, size=(5000, 3)) * 1.2 + [1, 2, 3]
    r = np.linalg.norm(p - [1, 2, 3], axis=1)
    inside = s.contains(p)
    assert inside.dtype == np.bool_
    clear = np.abs(r - 2.0) > 0.05  # the facets lie within 0.05 of the sphere
    np.testing.assert_array_equal(inside[clear], r[clear] < 2.0)


def test_occluded_agrees_with_closest_hits_and_threads_give_the_same_answers():
    v, f = icosphere(3)
    s = sahara.RayScene(v, f, threads=1)
    o, d = random_rays(5000)
    one = s.cast_rays(o, d)
    two = s.cast_rays(o, d, threads=2)
    for k in one:
        np.testing.assert_array_equal(one[k], two[k])
    np.testing.assert_array_equal(s.occluded(o, d), one["triangle"] >= 0)


@pytest.mark.parametrize("builder", ["spatial", "binned", "kd"])
def test_every_structure_gives_the_kd_trees_answers_bit_for_bit(builder):
    v, f = icosphere(3)
    v = np.vstack([v, v * 0.5 + 0.2])
    f = np.vstack([f, f + len(v) // 2])
    o, d = random_rays(5000, spread=1.5)
    kd = sahara.RayScene(v, f, accel="kd")
    bvh = sahara.RayScene(v, f, accel="bvh", builder=builder)
    a, b = kd.cast_rays(o, d), bvh.cast_rays(o, d)
    assert (a["triangle"] >= 0).sum() > 1000
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])
    np.testing.assert_array_equal(kd.occluded(o, d), bvh.occluded(o, d))
    np.testing.assert_array_equal(kd.count_intersections(o, d), bvh.count_intersections(o, d))


def test_stats_report_the_tree():
    v, f = icosphere(3)
    st = sahara.RayScene(v, f, builder="binned").stats()
    assert st["triangles"] == len(f) and st["builder"] == "binned" and st["accel"] == "bvh"
    st = sahara.RayScene(v, f, accel="kd", builder="sah").stats()
    assert st["triangles"] == len(f) and st["builder"] == "sah" and st["accel"] == "kd"
    assert st["sah_cost"] > 0 and st["nodes"] == st["inner"] + st["leaves"]
    assert st["memory_bytes"] > 0


def test_queries_release_the_gil():
    v, f = icosphere(5)
    s = sahara.RayScene(v, f, threads=1)
    o, d = random_rays(400_000)
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(1)
            done.wait(0.001)

    t = threading.Thread(target=tick)
    t.start()
    s.cast_rays(o, d)
    done.set()
    t.join()
    # The other thread ran while the query did (it would be stopped if
    # the query held the GIL).
    assert len(ticks) > 5


def write_rays(path, o, d, tmin=0.0, tmax=np.inf):
    r = np.zeros((len(o), 8), np.float32)
    r[:, 0:3], r[:, 3], r[:, 4:7], r[:, 7] = o, tmin, d, tmax
    r.tofile(path)


def test_the_same_bits_as_the_rust_queries(tmp_path, sahara_bin):
    """The command line traces a ray file with sahara-kd's batch queries and
    writes its hits; RayScene answers the same rays with the same bits."""
    v, f = icosphere(4)
    rng = np.random.default_rng(7)
    v = v * (1 + 0.1 * rng.random((len(v), 1)))  # a bumpy sphere
    mesh = tmp_path / "bumpy.obj"
    write_obj(mesh, v, f)
    o, d = random_rays(20_000, spread=1.5)
    tmax = np.where(np.arange(len(o)) % 3 == 0, 1.0, np.inf).astype(np.float32)
    rays = tmp_path / "rays.bin"
    write_rays(rays, o, d, 0.0, tmax)
    s = sahara.RayScene(v.astype(np.float32), f)
    hit_dtype = [("t", "<f4"), ("i", "<u4")]
    for any_hit in [False, True]:
        hits = tmp_path / "hits.bin"
        cmd = [sahara_bin, "bench", str(mesh), "--rays", str(rays), "--dump", "file", str(hits), "--runs", "1"]
        subprocess.run(cmd + (["--any-hit"] if any_hit else []), check=True, capture_output=True)
        want = np.fromfile(hits, dtype=hit_dtype)
        if any_hit:
            np.testing.assert_array_equal(s.occluded(o, d, tmax=tmax), want["i"] == 0xFFFFFFFE)
        else:
            got = s.cast_rays(o, d, tmax=tmax)
            assert (got["triangle"] >= 0).sum() > 5000
            np.testing.assert_array_equal(got["t"].view(np.uint32), want["t"].view(np.uint32))
            np.testing.assert_array_equal(got["triangle"].astype(np.int64) & 0xFFFFFFFF, want["i"])


def test_read_mesh_gives_the_command_lines_triangles(tmp_path):
    v, f = icosphere(1)
    path = tmp_path / "s.obj"
    write_obj(path, v, f)
    vv, ff = sahara.read_mesh(path)
    assert vv.dtype == np.float32 and ff.dtype == np.uint32
    # The same triangles in the same order (the vertices numbered as the reader numbers them).
    np.testing.assert_array_equal(vv[ff], v.astype(np.float32)[f])
    with pytest.raises(FileNotFoundError):
        sahara.read_mesh(tmp_path / "none.ply")
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    with pytest.raises(sahara.FormatError, match="bad.obj: line 2"):
        sahara.read_mesh(bad)


@pytest.mark.parametrize("mesh", ["bunny/bunny.ply", "dragon/dragon.ply", "sponza/sponza.obj"])
def test_agreement_with_embree_on_the_shared_meshes(tmp_path, sahara_bin, shared_scenes, mesh):
    """The benchmark protocol's agreement rule against Embree (embreex) on
    its diffuse rays: hit counts within 0.01% of the rays, t-sums within
    1e-4 relative."""
    embreex = pytest.importorskip("embreex.rtcore_scene")
    from embreex.mesh_construction import TriangleMesh

    mesh = shared_scenes / mesh
    rays = tmp_path / "rays.bin"
    subprocess.run([sahara_bin, "bench", str(mesh), "--sets", "diffuse", "--runs", "1",
                    "--threads", "1", "--dump-rays", "diffuse", str(rays)], check=True, capture_output=True)
    r = np.fromfile(rays, np.float32).reshape(-1, 8)
    o, d, tmin, tmax = np.ascontiguousarray(r[:, :3]), np.ascontiguousarray(r[:, 4:7]), r[:, 3], r[:, 7]
    v, f = sahara.read_mesh(mesh)
    ours = sahara.RayScene(v, f).cast_rays(o, d, tmin, tmax)["t"]
    scene = embreex.EmbreeScene()
    TriangleMesh(scene=scene, vertices=v, indices=f.astype(np.int32))
    e = scene.run(o, d, dists=tmax.copy(), output=1)
    theirs = np.where(e["primID"] >= 0, e["tfar"], np.inf)
    hit_o, hit_t = np.isfinite(ours), np.isfinite(theirs)
    assert hit_o.sum() > 10000
    assert abs(int(hit_o.sum()) - int(hit_t.sum())) <= 1e-4 * len(o)
    s_o, s_t = ours[hit_o].sum(dtype=np.float64), theirs[hit_t].sum(dtype=np.float64)
    assert abs(s_o - s_t) <= 1e-4 * s_o
