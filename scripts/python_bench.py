#!/usr/bin/env python3
"""Ray-casting speed of the Python package against embreex, trimesh's
default intersector and (when installed) Open3D's RaycastingScene.

For each mesh, the benchmark protocol's camera (`primary`) and `diffuse`
rays, written by `sahara bench MESH --dump-rays SET FILE`, are traced by
each library from Python, closest hit, on one and on two threads; the table
gives millions of rays a second (best of --runs). One thread is measured
by the process's CPU time (a busy neighbour on a shared machine disturbs it
less), two threads by wall time. trimesh's default intersector (pure numpy,
used when embreex is not installed) is timed on a --trimesh-rays sample
only: it would take hours on the full sets.

Every library's hits are checked against Sahara's by the protocol's
agreement rule (hit counts within 0.01% of the rays, t-sums within 1e-4
relative); the `same` column says whether they agree. `overhead` is the
Python call's extra time over the Rust query alone on one thread
(`sahara bench --rays FILE`'s one-call batch figure, by CPU time): with
new result arrays (the default), and with the arrays of an earlier call
reused (`out=`). `call` is the fixed cost of a call, a one-ray query, in
microseconds.

Usage (from the repository root, after `pip install ./crates/sahara-py
embreex trimesh rtree` in the Python that runs it):
  python scripts/python_bench.py [--meshes bunny,dragon,sponza] [--runs 5] [--trimesh-rays 5000]
"""

import argparse
import json
import os

# numpy's BLAS threads would add their spinning to the process's CPU time.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import subprocess
import sys
import tempfile
import threading
import time
import timeit

import numpy as np

import sahara

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.environ.get("SAHARA_SCENES", os.path.join(ROOT, "..", "shared", "scenes"))
MESHES = {
    "bunny": "bunny/bunny.ply",
    "dragon": "dragon/dragon.ply",
    "sponza": "sponza/sponza.obj",
}


def read_mesh(path):
    """The mesh's vertices and faces as the command line reads them, so
    that every library traces the same triangles in the same order."""
    v, f = sahara.read_mesh(path)
    return v, f.astype(np.int64)


def rays_of(binary, mesh, workdir):
    files = {s: os.path.join(workdir, f"{s}.rays") for s in ("primary", "diffuse")}
    cmd = [binary, "bench", mesh, "--sets", "primary,diffuse", "--runs", "1", "--threads", "1", "--json"]
    for s, f in files.items():
        cmd += ["--dump-rays", s, f]
    subprocess.run(cmd, check=True, capture_output=True)
    out = {}
    for s, f in files.items():
        r = np.fromfile(f, dtype=np.float32).reshape(-1, 8)
        out[s] = (np.ascontiguousarray(r[:, 0:3]), np.ascontiguousarray(r[:, 4:7]),
                  np.ascontiguousarray(r[:, 3]), np.ascontiguousarray(r[:, 7]), f)
    return out


def rust_batch_cpu(binary, mesh, rayfile, runs):
    """Mrays/s of one batch call on one thread by CPU time, from Rust."""
    p = subprocess.run([binary, "bench", mesh, "--rays", rayfile, "--runs", str(runs), "--threads", "1", "--json"],
                       check=True, capture_output=True, text=True)
    return json.loads(p.stdout)["sets"]["file"]["mrays_batch_1t_cpu"]


def best(f, runs, cpu):
    clock = time.process_time if cpu else time.perf_counter
    times = []
    for _ in range(runs):
        t0 = clock()
        out = f()
        times.append(clock() - t0)
    return min(times), out


def summary(t):
    hit = np.isfinite(t)
    return int(hit.sum()), float(np.sum(t[hit], dtype=np.float64))


def agree(a, b, n):
    return abs(a[0] - b[0]) <= 1e-4 * n and abs(a[1] - b[1]) <= 1e-4 * max(abs(a[1]), 1e-30)


def in_threads(f, o, d, tmax, threads):
    """`f` on `threads` slices of the rays, each in its own Python thread
    (for libraries that release the GIL but trace on the calling thread)."""
    parts = np.array_split(np.arange(len(o)), threads)
    out = [None] * threads

    def work(k):
        idx = parts[k]
        out[k] = f(o[idx[0]:idx[-1] + 1], d[idx[0]:idx[-1] + 1], tmax[idx[0]:idx[-1] + 1])

    ts = [threading.Thread(target=work, args=(k,)) for k in range(threads)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    return np.concatenate(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="bunny,dragon,sponza")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--trimesh-rays", type=int, default=20000)
    ap.add_argument("--sahara", default=os.path.join(ROOT, "target", "release", "sahara"))
    args = ap.parse_args()
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
    except ImportError:
        rtcore_scene = None
    try:
        import open3d as o3d
    except ImportError:
        o3d = None
    import trimesh
    from trimesh.ray.ray_triangle import RayMeshIntersector as TrimeshIntersector

    rows = []
    for name in args.meshes.split(","):
        path = os.path.join(SCENES, MESHES[name])
        v, f = read_mesh(path)
        with tempfile.TemporaryDirectory() as work:
            sets = rays_of(args.sahara, path, work)
            scene = sahara.RayScene(v, f)
            scene.stats()  # built before timing
            emb = None
            if rtcore_scene is not None:
                emb = rtcore_scene.EmbreeScene()
                TriangleMesh(scene=emb, vertices=v, indices=f.astype(np.int32))
            o3s = None
            if o3d is not None:
                o3s = o3d.t.geometry.RaycastingScene()
                o3s.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f.astype(np.uint32)))
            tm = TrimeshIntersector(trimesh.Trimesh(v, f, process=False))
            for set_name, (o, d, tmin, tmax, rayfile) in sets.items():
                n = len(o)
                rust = rust_batch_cpu(args.sahara, path, rayfile, args.runs)
                row = {"mesh": name, "set": set_name, "rays": n, "rust_1t": rust}
                for threads in (1, 2):
                    cpu = threads == 1
                    sec, out = best(lambda: scene.cast_rays(o, d, tmin, tmax, threads=threads)["t"], args.runs, cpu)
                    row[f"sahara_{threads}t"] = n / sec / 1e6
                    ref = summary(out)
                    if emb is not None:
                        def embree(oo, dd, tt):
                            r = emb.run(oo, dd, dists=tt.copy(), output=1)
                            return np.where(r["primID"] >= 0, r["tfar"], np.inf)

                        sec_e, te = best(lambda: in_threads(embree, o, d, tmax, threads), args.runs, cpu)
                        row[f"embree_{threads}t"] = n / sec_e / 1e6
                        row["embree_same"] = agree(summary(te), ref, n)
                    if o3s is not None:
                        rays = o3d.core.Tensor(np.hstack([o, d]))
                        sec_o, to = best(lambda: o3s.cast_rays(rays, nthreads=threads)["t_hit"].numpy(), args.runs, cpu)
                        row[f"open3d_{threads}t"] = n / sec_o / 1e6
                        row["open3d_same"] = agree(summary(to), ref, n)
                # trimesh's default intersector on the first rays, 10 at a
                # time (its memory grows with the rays of a call), for at
                # most --trimesh-rays rays or 60 s.
                done, t0 = 0, time.process_time()
                while done < min(args.trimesh_rays, n) and time.process_time() - t0 < 60:
                    tm.intersects_first(o[done:done + 10], d[done:done + 10])
                    done += len(o[done:done + 10])
                row["trimesh_1t"] = done / (time.process_time() - t0) / 1e6
                row["trimesh_rays"] = done
                row["overhead"] = rust / row["sahara_1t"] - 1.0
                out = scene.cast_rays(o, d, tmin, tmax)
                sec, _ = best(lambda: scene.cast_rays(o, d, tmin, tmax, out=out, threads=1), args.runs, True)
                row["overhead_out"] = rust * sec / n * 1e6 - 1.0
                one_o, one_d = o[:1].copy(), d[:1].copy()
                row["call_us"] = min(timeit.repeat(lambda: scene.cast_rays(one_o, one_d, threads=1),
                                                   number=2000, repeat=3)) / 2000 * 1e6
                rows.append(row)
                print(json.dumps(row), file=sys.stderr, flush=True)

    def fmt(x, digits=2):
        return "-" if x is None else f"{x:.{digits}f}"

    print("| mesh | set | rays | Sahara 1T | Sahara 2T | embreex 1T | embreex 2T | Open3D 1T | Open3D 2T "
          "| trimesh 1T, rays/s | Sahara / embreex 1T, 2T | Sahara / trimesh | overhead, out= | call, us "
          "| same hits |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        e1, e2 = r.get("embree_1t"), r.get("embree_2t")
        same = [k for k in ("embree", "open3d") if f"{k}_same" in r]
        print(f"| {r['mesh']} | {r['set']} | {r['rays']:,} | {fmt(r['sahara_1t'])} | {fmt(r['sahara_2t'])} "
              f"| {fmt(e1)} | {fmt(e2)} | {fmt(r.get('open3d_1t'))} | {fmt(r.get('open3d_2t'))} "
              f"| {r['trimesh_1t'] * 1e6:,.0f} "
              f"| {fmt(r['sahara_1t'] / e1 if e1 else None)}, {fmt(r['sahara_2t'] / e2 if e2 else None)} "
              f"| {r['sahara_1t'] / r['trimesh_1t']:,.0f}x "
              f"| {100 * r['overhead']:+.1f}%, {100 * r['overhead_out']:+.1f}% | {r['call_us']:.0f} "
              f"| {', '.join(k + (' yes' if r[f'{k}_same'] else ' NO') for k in same)} |")


if __name__ == "__main__":
    main()
