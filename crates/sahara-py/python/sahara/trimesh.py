"""trimesh's ray intersector interface over Sahara's kd-tree.

``RayMeshIntersector(mesh)`` answers ``intersects_first``,
``intersects_any``, ``intersects_id``, ``intersects_location`` and
``contains_points`` as trimesh's own intersectors do, so it can replace
``mesh.ray``::

    import trimesh, sahara.trimesh
    mesh = trimesh.creation.icosphere()
    mesh.ray = sahara.trimesh.RayMeshIntersector(mesh)
    mesh.contains([[0, 0, 0]])          # trimesh's call, Sahara's rays

trimesh itself is not needed to import this module: the intersector reads
the mesh's ``vertices``, ``faces``, ``bounds`` and hash, and
``contains_points`` uses trimesh's own parity test when trimesh is
installed (else ``RayScene.contains``).

Hits are exact (watertight, single precision): a ray through an edge
shared by two triangles hits both, as with trimesh's pure-numpy
intersector, and ``multiple_hits`` lists every triangle along each ray
once, nearest first; no ray is stepped past its hits, so no hit is lost or
repeated at grazing angles.
"""

from __future__ import annotations

from typing import Any, Optional, Tuple

import numpy as np

from ._sahara import RayScene

__all__ = ["RayMeshIntersector"]


class RayMeshIntersector:
    """Ray queries on a trimesh mesh with Sahara's accelerator (the
    eight-wide BVH by default).

    The structure is built at the first query and rebuilt when the mesh
    changes (its hash, as trimesh's intersectors check). ``accel``,
    ``builder`` and ``threads`` are those of ``sahara.RayScene``.
    """

    def __init__(
        self,
        geometry: Any,
        accel: str = "bvh",
        builder: Optional[str] = None,
        threads: Optional[int] = None,
    ):
        self.mesh = geometry
        self._accel = accel
        self._builder = builder
        self._threads = threads
        self._scene: Optional[RayScene] = None
        self._hash: Optional[int] = None

    @property
    def scene(self) -> RayScene:
        """The ``sahara.RayScene`` over the mesh as it is now."""
        h = self.mesh.__hash__()
        if self._scene is None or h != self._hash:
            self._scene = RayScene(
                np.asarray(self.mesh.vertices, dtype=np.float64),
                np.asarray(self.mesh.faces, dtype=np.int64),
                accel=self._accel,
                builder=self._builder,
                threads=self._threads,
            )
            self._hash = h
        return self._scene

    @staticmethod
    def _rays(ray_origins: Any, ray_directions: Any) -> Tuple[np.ndarray, np.ndarray]:
        o = np.asarray(ray_origins, dtype=np.float64)
        d = np.asarray(ray_directions, dtype=np.float64)
        if o.shape != d.shape:
            raise ValueError("Ray origin and direction don't match!")
        return o.reshape(-1, 3), d.reshape(-1, 3)

    def intersects_first(self, ray_origins: Any, ray_directions: Any, **kwargs: Any) -> np.ndarray:
        """The index of the first triangle each ray hits, -1 where none (int64)."""
        o, d = self._rays(ray_origins, ray_directions)
        return self.scene.cast_rays(o, d)["triangle"].astype(np.int64)

    def intersects_any(self, ray_origins: Any, ray_directions: Any, **kwargs: Any) -> np.ndarray:
        """Whether each ray hits the mesh (bool)."""
        o, d = self._rays(ray_origins, ray_directions)
        return self.scene.occluded(o, d)

    def intersects_id(
        self,
        ray_origins: Any,
        ray_directions: Any,
        return_locations: bool = False,
        multiple_hits: bool = True,
        max_hits: Optional[int] = None,
        **kwargs: Any,
    ):
        """The triangles the rays hit: ``(index_tri, index_ray)``, and the hit
        points as a third array with ``return_locations``. With
        ``multiple_hits`` every triangle along each ray (at most
        ``max_hits``, the nearest), else each ray's first hit; rays that miss
        do not appear. Ordered by ray, then by distance."""
        o, d = self._rays(ray_origins, ray_directions)
        hits = self.scene.all_hits(o, d, max_hits=max_hits if multiple_hits else 1)
        index_ray = hits["ray"]
        index_tri = hits["triangle"].astype(np.int64)
        if not return_locations:
            return index_tri, index_ray
        t = hits["t"].astype(np.float64)[:, None]
        locations = o[index_ray] + d[index_ray] * t
        return index_tri, index_ray, locations

    def intersects_location(
        self, ray_origins: Any, ray_directions: Any, multiple_hits: bool = True, **kwargs: Any
    ):
        """Where the rays hit: ``(locations, index_ray, index_tri)``."""
        index_tri, index_ray, locations = self.intersects_id(
            ray_origins, ray_directions, return_locations=True, multiple_hits=multiple_hits, **kwargs
        )
        return locations, index_ray, index_tri

    def contains_points(self, points: Any) -> np.ndarray:
        """Whether each point is inside the mesh, by trimesh's parity test
        (rays both ways, a second direction where they disagree) on Sahara's
        hits; undefined for points on the surface."""
        try:
            from trimesh.ray.ray_util import contains_points
        except ImportError:
            return self.scene.contains(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        return contains_points(self, points)
