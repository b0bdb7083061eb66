"""Type stubs of the native module `sahara._sahara` (see `sahara`)."""

from typing import Any, Dict, Optional, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Floats = Union[npt.ArrayLike, float]

class RayScene:
    """Triangle meshes in one kd-tree, for ray queries on numpy arrays.

    ``RayScene(vertices, faces)`` holds one mesh; ``add_mesh`` adds more,
    each with its id (0, 1, ...), and the tree is built at the next query.
    Every query releases the GIL and runs on ``threads`` threads (None: all).
    """

    def __init__(
        self,
        vertices: Optional[npt.ArrayLike] = None,
        faces: Optional[npt.ArrayLike] = None,
        *,
        builder: str = "sah",
        threads: Optional[int] = None,
    ) -> None: ...
    def add_mesh(self, vertices: npt.ArrayLike, faces: npt.ArrayLike) -> int:
        """Adds (N, 3) float vertices and (M, 3) integer faces; returns the mesh id."""
    @property
    def mesh_count(self) -> int: ...
    @property
    def triangle_count(self) -> int: ...
    def cast_rays(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        tmin: Optional[_Floats] = None,
        tmax: Optional[_Floats] = None,
        *,
        threads: Optional[int] = None,
    ) -> Dict[str, np.ndarray]:
        """Closest hits: ``t`` (inf on a miss), ``triangle``, ``mesh`` (-1 on a
        miss), ``u``, ``v``, ``normal`` (N, 3)."""
    def occluded(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        tmin: Optional[_Floats] = None,
        tmax: Optional[_Floats] = None,
        *,
        threads: Optional[int] = None,
    ) -> npt.NDArray[np.bool_]:
        """True where a triangle is hit with t in (tmin, tmax]."""
    def count_intersections(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        tmin: Optional[_Floats] = None,
        tmax: Optional[_Floats] = None,
        *,
        threads: Optional[int] = None,
    ) -> npt.NDArray[np.int32]:
        """The number of triangles each ray crosses in (tmin, tmax]."""
    def all_hits(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        tmin: Optional[_Floats] = None,
        tmax: Optional[_Floats] = None,
        *,
        max_hits: Optional[int] = None,
        threads: Optional[int] = None,
    ) -> Dict[str, np.ndarray]:
        """Every hit, ray by ray in order of t: ``ray``, ``t``, ``triangle``,
        ``mesh``, ``u``, ``v``."""
    def contains(
        self, points: npt.ArrayLike, *, samples: int = 3, threads: Optional[int] = None
    ) -> npt.NDArray[np.bool_]:
        """Inside tests by ray parity (majority of ``samples`` directions)."""
    def stats(self) -> Dict[str, Any]:
        """The tree's statistics, the SAH cost included."""
