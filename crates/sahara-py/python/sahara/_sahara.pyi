"""Type stubs of the native module `sahara._sahara` (see `sahara`)."""

import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

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
        accel: str = "bvh",
        builder: Optional[str] = None,
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
        out: Optional[Dict[str, np.ndarray]] = None,
        threads: Optional[int] = None,
    ) -> Dict[str, np.ndarray]:
        """Closest hits: ``t`` (inf on a miss), ``triangle``, ``mesh`` (-1 on a
        miss), ``u``, ``v``, ``normal`` (N, 3). ``out``: the dict an earlier
        call with as many rays returned, written over and returned."""
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

class FormatError(ValueError):
    """A file Sahara cannot read or write; the message names the file and line."""

class Scene:
    """A scene loaded from a file (or the built-in Cornell box)."""

    name: str
    description: str
    warnings: List[str]
    object_names: List[str]
    material_names: List[str]
    framing: Optional[str]
    @property
    def file_settings(self) -> Optional[Dict[str, Any]]: ...
    @property
    def triangle_count(self) -> int: ...

def load(
    path: str,
    *,
    camera: Optional[str] = None,
    sky: Optional[str] = None,
    defines: Optional[List[Tuple[str, str]]] = None,
) -> Scene: ...
def cornell_box(*, camera: Optional[str] = None, sky: Optional[str] = None) -> Scene: ...
def render(
    scene: Scene,
    *,
    threads: Optional[int] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
    output: Optional[Union[str, "os.PathLike[str]"]] = None,
    spp: Optional[int] = None,
    noise_threshold: Optional[float] = None,
    min_spp: Optional[int] = None,
    pass_spp: Optional[int] = None,
    width: Optional[int] = None,
    height: Optional[int] = None,
    integrator: Optional[str] = None,
    sampler: Optional[str] = None,
    path_loop: Optional[str] = None,
    light_sampler: Optional[str] = None,
    guiding: Optional[str] = None,
    filter: Optional[str] = None,
    seed: Optional[int] = None,
    time_limit: Optional[float] = None,
    accel: Optional[str] = None,
    builder: Optional[str] = None,
    exposure: Optional[float] = None,
    tonemap: Optional[str] = None,
    part: Optional[Union[str, Tuple[int, int]]] = None,
    split: Optional[str] = None,
    crop: Optional[Union[str, Sequence[float]]] = None,
    samples: Optional[Union[str, Tuple[int, int]]] = None,
    aovs: Optional[Union[str, Sequence[str]]] = None,
    denoise: Optional[bool] = None,
) -> Tuple[npt.NDArray[np.float32], Dict[str, np.ndarray]]: ...
def write(
    path: str,
    image: npt.ArrayLike,
    *,
    exposure: float = 0.0,
    tonemap: str = "clamp",
    metadata: Optional[List[Tuple[str, str]]] = None,
) -> None: ...
def names() -> Dict[str, List[str]]: ...
def read_mesh(path: str) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.uint32]]:
    """A mesh file's (N, 3) vertices and (M, 3) faces, as the command line reads it."""
