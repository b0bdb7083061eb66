"""Sahara for Python: exact SAH kd-tree ray queries on numpy arrays, and
Sahara's renderer.

- ``RayScene``: triangle meshes in a kd-tree; closest hits, occlusion,
  intersection counts, every hit along rays and inside tests, on numpy
  arrays, without the GIL, on Sahara's threads.
- ``sahara.trimesh.RayMeshIntersector``: the same queries behind trimesh's
  intersector interface (trimesh is an optional dependency).

See docs/python.md in the repository.
"""

from ._sahara import RayScene, __version__

__all__ = ["RayScene", "__version__"]
