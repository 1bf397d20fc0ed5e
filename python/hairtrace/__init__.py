"""hairtrace: physically based hair and fur rendering from Python.

The Chiang 2016 hair BSDF and Huang 2022's elliptical fibres on numpy arrays
(``HairBsdf``, ``HuangBsdf``, ``sigma_a_from_melanin``, ``sigma_a_from_color``), and whole
renders (``Scene``): from a scene file, a demo, or keywords and numpy strands, rendered to
a float32 ``Image`` (h, w, 3). docs/python.md in the repository says more; every render
setting is in ``SETTINGS``.

>>> import hairtrace
>>> image = hairtrace.Scene.demo("furball").render(spp=4, width=64, height=48)
>>> image.shape, image.dtype
((48, 64, 3), dtype('float32'))
"""

from ._image import Image
from ._native import (
    DEMOS,
    SETTINGS,
    SIGMA_A_PRESETS,
    HairBsdf,
    HuangBsdf,
    Scene,
    __version__,
    read_image,
    sigma_a_from_color,
    sigma_a_from_melanin,
    sigma_a_preset,
    write_image,
)

__all__ = [
    "DEMOS",
    "SETTINGS",
    "SIGMA_A_PRESETS",
    "HairBsdf",
    "HuangBsdf",
    "Image",
    "Scene",
    "__version__",
    "read_image",
    "sigma_a_from_color",
    "sigma_a_from_melanin",
    "sigma_a_preset",
    "write_image",
]
