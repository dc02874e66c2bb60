"""Type stubs of the extension module (the classes ``veach`` re-exports)."""

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class Error(Exception):
    """A scene, image or device veach cannot use (the CLI's one-line message)."""

class Interrupted(KeyboardInterrupt):
    """Ctrl-C stopped a render; ``image`` holds what it computed."""

    image: "Image"

class Scene:
    """A loaded glTF scene: the chosen scene, camera and variant of a file."""

    @property
    def path(self) -> str: ...
    @property
    def warnings(self) -> List[str]: ...
    def info(self) -> Dict[str, Any]:
        """What ``veach info`` says of the scene: triangles, meshes, instances, lights,
        materials, textures, cameras, extensions, bounds."""

class Image:
    """A rendered, read, merged or denoised image."""

    @property
    def rgb(self) -> npt.NDArray[np.float32]:
        """Linear radiance, (H, W, 3) float32 (the denoised image when denoised)."""
    @property
    def noisy(self) -> npt.NDArray[np.float32]:
        """The mean of the samples, before denoising, (H, W, 3) float32."""
    @property
    def stats(self) -> Dict[str, Any]:
        """What ``veach render --stats-json`` writes of this render."""
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def spp(self) -> int: ...
    @property
    def denoised(self) -> bool: ...
    def aov(self, name: str) -> npt.NDArray[np.float32]:
        """"albedo", "normal" (H, W, 3); "depth", "spp" (H, W); "variance" (H, W, 3)."""
    def save(self, path: str, exposure: float = 0.0, tonemap: str = "clamp") -> None:
        """PNG (tone-mapped, sRGB) or EXR (linear, with the film and job), atomically."""
    def _repr_png_(self) -> bytes: ...

def load(path: str, scene: Optional[int], camera: Optional[str], variant: Optional[str]) -> Scene: ...
def render(
    scene: Scene,
    width: int,
    height: int,
    spp: int,
    max_depth: int,
    seed: int,
    backend: str,
    time: Optional[float],
    noise_threshold: Optional[float],
    min_samples: Optional[int],
    strategy: Optional[str],
    sampler: Optional[str],
    light_sampler: Optional[str],
    aovs: List[str],
    denoise: bool,
    denoise_quality: str,
    env_map: Optional[str],
    env_color: Optional[Tuple[float, float, float]],
    env_strength: float,
    clamp_direct: Optional[float],
    clamp_indirect: Optional[float],
    aperture: float,
    focus_distance: Optional[float],
    progress: Optional[Callable[[int, int, float], object]],
) -> Image: ...
def read(path: str) -> Image: ...
def read_rgb(path: str) -> npt.NDArray[np.float32]: ...
def merge(paths: Sequence[str]) -> Image: ...
def denoise(image: Image, quality: str = "balanced", backend: str = "auto") -> Image: ...
