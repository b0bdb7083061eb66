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

import errno
import os
import sys
import time
import warnings
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
    if more_defines and not os.fspath(path).lower().endswith(".xml"):
        # Only a Mitsuba scene takes parameters: anything else is a
        # mistyped keyword, said as Python says one.
        raise TypeError(
            f"load() got an unexpected keyword argument {next(iter(more_defines))!r} "
            "(keyword arguments other than camera, sky and defines are the parameters "
            "of a Mitsuba scene, .xml)"
        )
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
    else one line rewritten in place on a terminal, and plain lines now and
    then elsewhere (a log, a notebook's captured stderr), as the command
    line prints them."""

    #: Seconds between plain lines where stderr is not a terminal.
    EVERY = 10.0

    def __init__(self, label: str):
        self.label, self.bar, self.start = label, None, time.monotonic()
        self.last_line = None
        try:
            from tqdm.auto import tqdm

            self.tqdm = tqdm
        except ImportError:
            self.tqdm = None
        try:
            self.terminal = sys.stderr.isatty()
        except (AttributeError, ValueError):
            self.terminal = False
        self.drawn = False

    def __call__(self, done: int, total: int) -> None:
        if self.tqdm is not None:
            if self.bar is None:
                self.bar = self.tqdm(total=total, desc=self.label, unit="tile", leave=False)
            self.bar.total = total
            self.bar.n = done
            self.bar.refresh()
            return
        percent = 100 * done // max(total, 1)
        elapsed = time.monotonic() - self.start
        if not self.terminal:
            # No line rewritten in place where stderr is not a terminal:
            # a plain line now and then.
            now = time.monotonic()
            if self.last_line is None or now - self.last_line >= self.EVERY:
                self.last_line = now
                sys.stderr.write(f"{self.label}: {percent}% done, {elapsed:.0f} s\n")
                sys.stderr.flush()
            return
        width = 30
        filled = width * done // max(total, 1)
        line = f"\r{self.label} [{'#' * filled}{'.' * (width - filled)}] {percent:3d}% {elapsed:.0f} s"
        sys.stderr.write(line)
        sys.stderr.flush()
        self.drawn = True

    def close(self, finished: bool = True) -> None:
        if self.bar is not None:
            self.bar.close()
        elif self.tqdm is None and self.terminal:
            if self.drawn:
                sys.stderr.write("\r" + " " * 60 + "\r")
                sys.stderr.flush()
        elif self.tqdm is None and self.last_line is not None:
            # The plain lines end on the render's end, each on its own line.
            elapsed = time.monotonic() - self.start
            end = "100% done, finished" if finished else "stopped"
            sys.stderr.write(f"{self.label}: {end}, {elapsed:.0f} s\n")
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
    ``height``, ``integrator``, ``sampler``, ``light_sampler``,
    ``guiding``, ``filter``, ``seed``, ``pass_spp``, ``accel``,
    ``builder``; ``path_loop`` (``"auto"``, ``"lanes"``,
    ``"lanes-no-refill"``, ``"scalar"``: how the path tracer traces its
    samples); ``noise_threshold`` and ``min_spp``
    (adaptive sampling); ``time_limit`` (seconds: without ``spp`` the
    passes go on until it is up); ``aovs`` (any of ``albedo``, ``normal``,
    ``depth``, ``position``, ``uv``, ``variance``, ``object``,
    ``material``; one name or a sequence of names); ``denoise`` (Intel Open Image Denoise, ``pip install
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
    rendering on ``threads`` threads (None or 0: all, at most 1024);
    Ctrl-C stops the render after the tiles under way and raises
    ``KeyboardInterrupt``. A setting out of range raises ``ValueError``, of
    the wrong type (``spp=2.5``, ``spp="16"``) ``TypeError``, a render
    larger than the memory available ``MemoryError``, each naming the
    argument at fault.
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
    finished = False
    try:
        image, passes = _sahara.render(scene, threads=threads, progress=callback, **settings)
        finished = True
    finally:
        if bar is not None:
            bar.close(finished)
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
    The file is written beside the target and renamed over it.

    Float images are linear. ``uint8`` and ``uint16`` images are read as
    PIL and imageio give them, sRGB-encoded codes (0 to 255, 0 to 65535),
    and decoded to linear first (so an 8-bit image read with PIL is
    written back to the same PNG codes); other integer types are a
    ``TypeError``. NaN values are written as black (PNG) or NaN (EXR),
    with a ``RuntimeWarning`` that counts them. A folder is an
    ``IsADirectoryError``."""
    target = os.fspath(path)
    if os.path.isdir(target):
        raise IsADirectoryError(
            errno.EISDIR, "is a folder; give a file name ending in .png or .exr", target
        )
    image = _linear_image(image, target)
    items = [(str(k), str(v)) for k, v in (metadata or {}).items()]
    _sahara.write(target, image, exposure=exposure, tonemap=tonemap, metadata=items or None)


def _linear_image(image: Any, target: str) -> Any:
    """An image for ``write`` as linear floats: 8-bit and 16-bit unsigned
    codes decoded from sRGB; NaN counted and warned of."""
    a = np.asarray(image)
    if a.dtype == np.uint8 or a.dtype == np.uint16:
        c = a.astype(np.float64) / float(np.iinfo(a.dtype).max)
        linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
        return linear.astype(np.float32)
    if a.dtype.kind in "biu":
        raise TypeError(
            f"image: {a.dtype} pixels cannot be written; give linear floats, or uint8 or "
            "uint16 sRGB-encoded codes (as PIL and imageio read images)"
        )
    if a.dtype.kind == "f":
        nan = int(np.count_nonzero(np.isnan(a)))
        if nan:
            written = "NaN" if target.lower().endswith(".exr") else "black"
            warnings.warn(
                f"image: {nan} of {a.size} values are NaN; they are written as {written}",
                RuntimeWarning,
                stacklevel=3,
            )
    return image
