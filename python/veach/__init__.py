"""veach: a physically based path tracer built around multiple importance sampling.

>>> import veach
>>> image = veach.render("assets/cornell-box.gltf", width=128, height=128, spp=16)
>>> image.rgb.shape, image.rgb.dtype
((128, 128, 3), dtype('float32'))
>>> image.save("cornell-box.png")

``render`` releases the GIL while it works; Ctrl-C stops it within a chunk (a quarter of a
second) and raises ``veach.Interrupted`` (a ``KeyboardInterrupt``) whose ``.image`` holds
what was computed. Errors carry the command line's one-line messages: ``FileNotFoundError``
for a missing file, ``ValueError`` for a bad argument, ``veach.Error`` for a scene, image or
device veach cannot use.
"""

from __future__ import annotations

import os
import sys
import tempfile
from typing import TYPE_CHECKING, Callable, Iterable, Optional, Sequence, Tuple, Union

# Mesa's window-system code complains on every device it opens when XDG_RUNTIME_DIR is unset
# (headless machines, CI); the command line gives it a private directory too.
if sys.platform.startswith("linux") and not os.environ.get("XDG_RUNTIME_DIR"):
    _runtime = os.path.join(tempfile.gettempdir(), f"veach-xdg-runtime-{os.getuid()}")
    try:
        os.makedirs(_runtime, mode=0o700, exist_ok=True)
        os.environ["XDG_RUNTIME_DIR"] = _runtime
    except OSError:
        pass

from . import _veach  # noqa: E402

if TYPE_CHECKING:
    import numpy
from ._veach import Error, Image, Interrupted, Scene

__all__ = ["Error", "Image", "Interrupted", "Scene", "load", "render", "read", "read_rgb", "merge", "denoise"]
__version__ = _veach.__version__

PathLike = Union[str, "os.PathLike[str]"]
Progress = Callable[[int, int, float], object]


def load(
    path: PathLike,
    scene: Optional[int] = None,
    camera: Optional[str] = None,
    variant: Optional[str] = None,
) -> Scene:
    """Loads a glTF 2.0 file (.gltf or .glb): its default scene (or ``scene``, by index), its
    first camera (or ``camera``, by node name; else a view framing the scene) and its default
    materials (or a KHR_materials_variants ``variant``)."""
    return _veach.load(os.fspath(path), scene, camera, variant)


def _environment(env) -> Tuple[Optional[str], Optional[Tuple[float, float, float]]]:
    """``env``: None (the scene's own), a path to an equirectangular .hdr/.exr map, a grey
    level, or an (r, g, b) radiance."""
    if env is None:
        return None, None
    if isinstance(env, (str, os.PathLike)):
        return os.fspath(env), None
    if isinstance(env, (int, float)):
        return None, (float(env),) * 3
    try:
        rgb = tuple(float(c) for c in env)
    except TypeError:
        raise ValueError(f"env {env!r}: expected a path, a number or (r, g, b)") from None
    if len(rgb) != 3:
        raise ValueError(f"env {env!r}: expected three values (r, g, b)")
    return None, rgb


class _Bar:
    """A tqdm bar over samples per pixel, when tqdm is installed."""

    def __init__(self, total: int):
        from tqdm.auto import tqdm

        self.bar = tqdm(total=total, unit="spp", leave=False)
        self.done = 0

    def __call__(self, done: int, total: int, seconds: float) -> None:
        self.bar.update(done - self.done)
        self.done = done

    def close(self) -> None:
        self.bar.close()


def render(
    scene: Union[Scene, PathLike],
    width: int = 512,
    height: int = 512,
    spp: int = 64,
    max_depth: int = 8,
    seed: int = 0,
    backend: str = "auto",
    time: Optional[float] = None,
    noise_threshold: Optional[float] = None,
    light_sampler: Optional[str] = None,
    aovs: Iterable[str] = (),
    denoise: bool = False,
    env=None,
    progress: Union[bool, Progress, None] = True,
    *,
    min_samples: Optional[int] = None,
    strategy: Optional[str] = None,
    sampler: Optional[str] = None,
    denoise_quality: str = "balanced",
    env_strength: float = 1.0,
    clamp_direct: Optional[float] = None,
    clamp_indirect: Optional[float] = None,
    aperture: float = 0.0,
    focus_distance: Optional[float] = None,
) -> Image:
    """Renders a scene (a ``Scene`` or a glTF path) as ``veach render`` does, with the same
    defaults: 512x512, 64 spp, max depth 8, seed 0, the faster engine for this machine.

    - ``time``: stop after this many seconds of rendering (``spp`` is then a cap).
    - ``noise_threshold``: adaptive sampling (pixels stop once their error is below it).
    - ``light_sampler``: "ris" (the default: the light tree's candidates resampled by their
      unshadowed contribution at glossy surfaces), "tree" or "power".
    - ``aovs``: any of "albedo", "normal", "depth" (``Image.aov(name)``).
    - ``denoise``: run Open Image Denoise's network; ``Image.rgb`` is then the denoised image.
    - ``env``: a .hdr/.exr path, a grey level or (r, g, b) replacing the scene's environment.
    - ``progress``: True for a tqdm bar (when tqdm is installed), False or None for none, or a
      callable ``fn(done, total, seconds)`` called after every chunk of samples.
    - ``strategy``: "mis-power" (the default), "mis-balance", "bsdf" or "light".

    The same seed gives the same image, bit for bit, as the command line.
    """
    if not isinstance(scene, Scene):
        scene = load(scene)
    if isinstance(aovs, str):
        aovs = (aovs,)
    env_map, env_color = _environment(env)
    bar = None
    callback = None
    if callable(progress):
        callback = progress
    elif progress:
        try:
            bar = _Bar(spp)
            callback = bar
        except ImportError:
            callback = None
    try:
        return _veach.render(
            scene,
            _count("width", width),
            _count("height", height),
            _count("spp", spp),
            _count("max_depth", max_depth, 0),
            _count("seed", seed, 0),
            backend,
            None if time is None else float(time),
            None if noise_threshold is None else float(noise_threshold),
            None if min_samples is None else _count("min_samples", min_samples, 0),
            strategy,
            sampler,
            light_sampler,
            [str(a) for a in aovs],
            bool(denoise),
            denoise_quality,
            env_map,
            env_color,
            float(env_strength),
            None if clamp_direct is None else float(clamp_direct),
            None if clamp_indirect is None else float(clamp_indirect),
            float(aperture),
            None if focus_distance is None else float(focus_distance),
            callback,
        )
    finally:
        if bar is not None:
            bar.close()


def _count(name: str, value, least: int = 1) -> int:
    """An integer argument, refused with a ValueError naming it when it is not one."""
    if isinstance(value, bool) or not isinstance(value, int) and not hasattr(value, "__index__"):
        raise ValueError(f"{name} {value!r}: expected an integer")
    value = int(value)
    if value < least or value >= 2**32:
        raise ValueError(f"{name} {value}: expected an integer in {least}..{2**32 - 1}")
    return value


def read(path: PathLike) -> Image:
    """Reads an EXR written by veach (a render, a checkpoint or a farm part)."""
    return _veach.read(os.fspath(path))


def read_rgb(path: PathLike) -> "numpy.ndarray":
    """Any RGB EXR (a reference from another renderer, say) as linear float32 (H, W, 3)."""
    return _veach.read_rgb(os.fspath(path))


def merge(paths: Sequence[PathLike]) -> Image:
    """Merges farm parts (veach EXRs of disjoint sample ranges or tiles of one job) exactly,
    as ``veach merge`` does."""
    return _veach.merge([os.fspath(p) for p in paths])


def denoise(image: Union[Image, PathLike], quality: str = "balanced", backend: str = "auto") -> Image:
    """Denoises a render (an ``Image`` or a veach EXR) with Open Image Denoise's network,
    using its albedo and normal AOVs when it has them; ``quality`` "balanced" or "fast"."""
    if not isinstance(image, Image):
        image = read(image)
    return _veach.denoise(image, quality, backend)

