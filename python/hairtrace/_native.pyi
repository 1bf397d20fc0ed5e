"""Type stubs of the native module (python/src); ``hairtrace`` re-exports every name."""

import os
from typing import Any, Callable, Iterable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._image import Image

__version__: str
SETTINGS: list[str]
DEMOS: list[str]
SIGMA_A_PRESETS: list[str]

ArrayLike = npt.ArrayLike
F32 = npt.NDArray[np.float32]
Path = Union[str, os.PathLike[str]]

class HairBsdf:
    """The Chiang 2016 hair BSDF for one parameter set; left-out parameters are brown hair's."""

    def __init__(
        self,
        sigma_a: Optional[Sequence[float]] = None,
        eta: Optional[float] = None,
        beta_m: Optional[float] = None,
        beta_n: Optional[float] = None,
        alpha: Optional[float] = None,
    ) -> None: ...
    @property
    def sigma_a(self) -> list[float]: ...
    @property
    def eta(self) -> float: ...
    @property
    def beta_m(self) -> float: ...
    @property
    def beta_n(self) -> float: ...
    @property
    def alpha(self) -> float: ...
    def eval(self, h: ArrayLike, wo: ArrayLike, wi: ArrayLike) -> tuple[F32, F32]:
        """f (n, 3) and pdf (n,) for h (n,) and unit wo, wi (n, 3)."""
    def pdf(self, h: ArrayLike, wo: ArrayLike, wi: ArrayLike) -> F32:
        """The density (n,) of ``sample`` at wi."""
    def sample(self, h: ArrayLike, wo: ArrayLike, u: ArrayLike) -> tuple[F32, F32, F32]:
        """wi (n, 3), f (n, 3), pdf (n,) drawn from u (n, 3) in [0, 1); pdf 0: none."""

class HuangBsdf:
    """The Huang 2022 model of elliptical fibres; left-out parameters are brown, round hair's."""

    def __init__(
        self,
        sigma_a: Optional[Sequence[float]] = None,
        eta: Optional[float] = None,
        roughness: Optional[float] = None,
        aspect: Optional[float] = None,
        alpha: Optional[float] = None,
    ) -> None: ...
    @property
    def sigma_a(self) -> list[float]: ...
    @property
    def eta(self) -> float: ...
    @property
    def roughness(self) -> float: ...
    @property
    def aspect(self) -> float: ...
    @property
    def alpha(self) -> float: ...
    def eval(
        self,
        h: ArrayLike,
        wo: ArrayLike,
        wi: ArrayLike,
        major: Optional[ArrayLike] = None,
        jitter: Optional[ArrayLike] = None,
        field: str = "near",
    ) -> tuple[F32, F32]:
        """f (n, 3) and pdf (n,); ``major`` (n, 3) across the fibre (None: +y), ``jitter``
        (n, 2) in [0, 1) (None: 0.5), ``field`` "near", "far" or "far_lit"."""
    def pdf(
        self,
        h: ArrayLike,
        wo: ArrayLike,
        wi: ArrayLike,
        major: Optional[ArrayLike] = None,
        jitter: Optional[ArrayLike] = None,
        field: str = "near",
    ) -> F32:
        """The density (n,) of ``sample`` at wi."""
    def sample(
        self,
        h: ArrayLike,
        wo: ArrayLike,
        u: ArrayLike,
        major: Optional[ArrayLike] = None,
        jitter: Optional[ArrayLike] = None,
        field: str = "near",
    ) -> tuple[F32, F32, F32]:
        """wi (n, 3), f (n, 3), pdf (n,) drawn from u (n, 3) in [0, 1); pdf 0: none."""

def sigma_a_from_melanin(eumelanin: ArrayLike, pheomelanin: Optional[ArrayLike] = None) -> F32:
    """sigma_a (..., 3) from melanin concentrations (>= 0)."""

def sigma_a_from_color(color: ArrayLike, beta_n: Optional[float] = None) -> F32:
    """sigma_a (..., 3) that makes a fibre look like ``color`` (..., 3) in (0, 1]."""

def sigma_a_preset(name: str) -> F32:
    """The sigma_a (3,) of a named hair colour (``SIGMA_A_PRESETS``)."""

def write_image(path: Path, pixels: ArrayLike) -> None:
    """Writes linear pixels (h, w) or (h, w, c); the format by the extension."""

def read_image(path: Path) -> F32:
    """An image file's pixels (h, w, c), linear float32."""

class Scene:
    """A scene from a file, a demo, or keywords and numpy strands (docs/python.md)."""

    def __init__(self) -> None: ...
    @staticmethod
    def load(path: Path, frame: Optional[float] = None) -> Scene:
        """A scene file, its groom files read at ``frame`` (``render --frame``)."""
    @staticmethod
    def demo(name: str = "furball") -> Scene: ...
    def set(self, **settings: Any) -> None:
        """Render settings by name (``SETTINGS``), all valid or none set."""
    @property
    def settings(self) -> list[tuple[str, str]]: ...
    @property
    def materials(self) -> list[str]: ...
    @property
    def builds(self) -> int: ...
    @property
    def notes(self) -> list[str]: ...
    def set_material(self, name: str, **keys: Any) -> None: ...
    def add_light(self, **keys: Any) -> None: ...
    def set_lights(self, lights: list[dict[str, Any]]) -> None: ...
    def set_camera(self, **keys: Any) -> None: ...
    def add_groom(self, frame: Optional[float] = None, **keys: Any) -> None:
        """A ``[[groom]]``'s keys; a file read at ``frame`` over the scene's shutter."""
    def add_mesh(self, **keys: Any) -> None: ...
    def add_curves(
        self,
        points: Union[ArrayLike, Sequence[ArrayLike]],
        counts: ArrayLike,
        material: str,
        basis: str = "bspline",
        shape: str = "auto",
        colors: Optional[ArrayLike] = None,
    ) -> None:
        """Float4 control points (n, 4), or at K time steps: (K, n, 4) or K (n, 4) arrays."""
    def add_triangles(
        self,
        positions: Union[ArrayLike, Sequence[ArrayLike]],
        triangles: ArrayLike,
        material: str,
        normals: Optional[ArrayLike] = None,
    ) -> None:
        """Vertices (n, 3), or at K time steps: (K, n, 3) or K (n, 3) arrays."""
    def add_strands(
        self,
        points: ArrayLike,
        radii: ArrayLike,
        counts: ArrayLike,
        colors: Optional[ArrayLike] = None,
        **keys: Any,
    ) -> None: ...
    def render(
        self,
        aovs: Iterable[str] = (),
        progress: Union[None, bool, Callable[[int, int], Optional[bool]]] = None,
        **settings: Any,
    ) -> Image: ...
