"""Sahara for Python: exact SAH kd-tree ray queries on numpy arrays, and
Sahara's renderer.

- ``RayScene``: triangle meshes in a kd-tree; closest hits, occlusion,
  intersection counts, every hit along rays and inside tests, on numpy
  arrays, without the GIL, on Sahara's threads.
- ``sahara.trimesh.RayMeshIntersector``: the same queries behind trimesh's
  intersector interface (trimesh is an optional dependency).
- ``read_mesh``: a mesh file's vertices and faces as Sahara reads them.
- ``load``, ``cornell_box``, ``render``, ``write``: scenes read as the
  ``sahara`` command line reads them, rendered to numpy arrays (the same
  image for the same seed), written as PNG or EXR by the same writer.

See docs/python.md in the repository.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any, Callable, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _sahara
from ._sahara import FormatError, RayScene, Scene, __version__, cornell_box, names, read_mesh

__all__ = [
    "FormatError",
    "RayScene",
    "Scene",
    "__version__",
    "cornell_box",
    "load",
    "names",
    "read_mesh",
    "render",
    "write",
]

PathLike = Union[str, "os.PathLike[str]"]


def load(
    path: PathLike,
    *,
    camera: Optional[str] = None,
    sky: Optional[str] = None,
    defines: Optional[Mapping[str, Any]] = None,
    **more_defines: Any,
) -> Scene:
    """Loads a scene or mesh file as ``sahara render`` does: ``.toml``,
    ``.pbrt``, ``.pbrt.gz``, ``.xml`` (Mitsuba), ``.obj``, ``.ply``,
    ``.gltf``, ``.glb``.

    Keyword arguments other than ``camera`` and ``sky`` (and the entries
    of ``defines``) are a Mitsuba scene's parameters, as ``-D name=value``:
    ``sahara.load("scene.xml", spp=16)``. ``camera``: a camera sidecar
    file or a glTF camera's name (meshes only); ``sky``: ``auto``,
    ``default``, ``none`` or an environment image. Raises
    ``FileNotFoundError``, or ``sahara.FormatError`` (a ``ValueError``)
    with the command line's one-line message naming the file and line.
    """
    d = {str(k): _define(v) for k, v in dict(defines or {}, **more_defines).items()}
    return _sahara.load(os.fspath(path), camera=camera, sky=sky, defines=list(d.items()) or None)


def _define(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (list, tuple)):
        return ", ".join(str(x) for x in v)
    return str(v)


class _Bar:
    """A progress bar on stderr: tqdm's (notebook-aware) when installed,
    else one line rewritten in place."""

    def __init__(self, label: str):
        self.label, self.bar, self.start = label, None, time.monotonic()
        try:
            from tqdm.auto import tqdm

            self.tqdm = tqdm
        except ImportError:
            self.tqdm = None

    def __call__(self, done: int, total: int) -> None:
        if self.tqdm is not None:
            if self.bar is None:
                self.bar = self.tqdm(total=total, desc=self.label, unit="tile", leave=False)
            self.bar.total = total
            self.bar.n = done
            self.bar.refresh()
            return
        width = 30
        filled = width * done // max(total, 1)
        line = f"\r{self.label} [{'#' * filled}{'.' * (width - filled)}] {100 * done // max(total, 1):3d}% {time.monotonic() - self.start:.0f} s"
        sys.stderr.write(line)
        sys.stderr.flush()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        elif self.tqdm is None:
            sys.stderr.write("\r" + " " * 60 + "\r")
            sys.stderr.flush()


def render(
    scene: Union[Scene, PathLike],
    *,
    progress: Union[bool, Callable[[int, int], Any]] = True,
    threads: Optional[int] = None,
    **settings: Any,
) -> Union[np.ndarray, Tuple[np.ndarray, Dict[str, np.ndarray]]]:
    """Renders a scene (a ``Scene`` or a file's path) through the request
    ``sahara render`` makes: the settings given override the file's
    settings, which override the defaults (512 x 512, 64 spp, the path
    tracer, seed 0); the same settings give the same image, bit for bit,
    as the command line, and with ``output`` the same file.

    The settings are the command line's render options as keywords
    (``sahara.names()["setting"]`` lists them): ``spp``, ``width``,
    ``height``, ``integrator``, ``sampler``, ``filter``, ``seed``,
    ``pass_spp``, ``builder``; ``noise_threshold`` and ``min_spp``
    (adaptive sampling); ``time_limit`` (seconds: without ``spp`` the
    passes go on until it is up); ``aovs`` (any of ``albedo``, ``normal``,
    ``depth``, ``position``, ``uv``, ``variance``, ``object``,
    ``material``); ``denoise`` (Intel Open Image Denoise, ``pip install
    pyoidn``); ``output`` (a ``.png`` or ``.exr`` file written as the
    command line writes it, with ``exposure`` and ``tonemap``); ``part``
    (``(i, n)``), ``split`` (``"tiles"`` or ``"samples"``), ``crop``
    (``(x0, x1, y0, y1)``) and ``samples`` (``(start, end)``): a piece of
    the frame, its ``output`` a part file for ``sahara merge``.

    Returns the linear RGB image, a float32 array (height, width, 3), of
    the crop window or piece if one is asked for; with ``aovs`` a pair
    ``(image, passes)`` whose dict holds one array per pass.
    ``progress``: a bar on stderr (True), none (False), or a function
    called with (tiles done, tiles in all). The GIL is released while
    rendering on ``threads`` threads (None: all); Ctrl-C stops the render
    after the tiles under way and raises ``KeyboardInterrupt``. A setting
    out of range raises ``ValueError``, of the wrong type ``TypeError``, a
    render larger than the memory available ``MemoryError``, each naming
    what is at fault.
    """
    if not isinstance(scene, Scene):
        scene = load(scene)
    bar = None
    if progress is True:
        bar = _Bar(f"rendering {scene.name}")
        callback = bar
    elif callable(progress):
        callback = progress
    else:
        callback = None
    try:
        image, passes = _sahara.render(scene, threads=threads, progress=callback, **settings)
    finally:
        if bar is not None:
            bar.close()
    return (image, passes) if settings.get("aovs") else image


def write(
    path: PathLike,
    image: Any,
    *,
    exposure: float = 0.0,
    tonemap: str = "clamp",
    metadata: Optional[Mapping[str, Any]] = None,
) -> None:
    """Writes a linear RGB image, (height, width, 3), as ``sahara render``
    writes its output: ``.exr`` as linear 32-bit floats, ``.png`` as 8-bit
    sRGB after ``exposure`` (stops) and ``tonemap`` (``clamp`` or
    ``filmic``); ``metadata``'s entries as the file's text attributes.
    The file is written beside the target and renamed over it."""
    items = [(str(k), str(v)) for k, v in (metadata or {}).items()]
    _sahara.write(os.fspath(path), image, exposure=exposure, tonemap=tonemap, metadata=items or None)
