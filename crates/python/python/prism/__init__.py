"""Prism on NumPy arrays: colorimetry, spectral rendering, tone mapping, image metrics and
image files, computed by the same library functions as the ``prism`` command line, so that
results equal the CLI's (docs/python.md).

>>> import prism
>>> prism.color("colorchecker:dark skin")["Lab"]
>>> r = prism.render("scenes/cornell-box.json", spp=16, resolution=(128, 128))
>>> display = prism.tonemap(r.rgb, op="reinhard02", encode=True)
"""

from ._prism import (
    ArgumentError,
    Image,
    ImageError,
    PrismError,
    Render,
    RenderError,
    SceneError,
    SpectrumError,
    color,
    compare,
    operators,
    read_image,
    render,
    tonemap,
    write_image,
)

__all__ = [
    "ArgumentError",
    "Image",
    "ImageError",
    "PrismError",
    "Render",
    "RenderError",
    "SceneError",
    "SpectrumError",
    "color",
    "compare",
    "operators",
    "read_image",
    "render",
    "tonemap",
    "write_image",
]
