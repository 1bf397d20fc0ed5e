"""The image a render returns: a float32 numpy array with its AOVs and statistics."""

from __future__ import annotations

import os
import tempfile
from typing import Any, Optional

import numpy as np

from ._native import write_image


class Image(np.ndarray):
    """A render's linear RGB, float32, shape (h, w, 3): a numpy array like any other.

    ``aovs`` holds the AOVs asked for ("albedo" (h, w, 3), "depth" and "strand" (h, w)),
    ``stats`` the render's statistics (seconds, spp, rays, noise, ...), ``complete``
    whether it finished (False when a progress callback stopped it). In Jupyter the image
    shows itself, encoded as the command line writes PNGs (sRGB, clamped).
    """

    aovs: dict[str, np.ndarray]
    stats: dict[str, Any]
    complete: bool

    def __new__(
        cls,
        rgb: Any,
        aovs: Optional[dict[str, np.ndarray]] = None,
        stats: Optional[dict[str, Any]] = None,
        complete: bool = True,
    ) -> Image:
        image = np.asarray(rgb, dtype=np.float32).view(cls)
        image.aovs = dict(aovs or {})
        image.stats = dict(stats or {})
        image.complete = complete
        return image

    def __array_finalize__(self, obj: Any) -> None:
        # Views and slices keep what the render said about the whole image.
        self.aovs = getattr(obj, "aovs", {})
        self.stats = getattr(obj, "stats", {})
        self.complete = getattr(obj, "complete", True)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Writes the image; the format by the extension (.exr, .png, .jpg, .tif)."""
        write_image(path, np.asarray(self))

    def _repr_png_(self) -> Optional[bytes]:
        if self.ndim not in (2, 3) or not np.isfinite(self).all():
            return None
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "image.png")
            self.save(path)
            with open(path, "rb") as f:
                return f.read()
