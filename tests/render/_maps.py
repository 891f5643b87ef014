"""Environment-map files for the render tests (tests/render/test_envmap.py and
tests/render/base/test_summed_envmap.py): the frame that puts a map's +y on the scene's +z and
an OpenEXR writer that returns the file's path and SHA-256, as a scene's ``envmap`` light takes
them."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

from spectrinsic.mitsuba_import import import_mitsuba

__all__ = ["UP_IS_Z", "write_map"]

#: Row-major 3 x 3 rotation taking Mitsuba's envmap frame (+y up) to a scene whose up is +z.
UP_IS_Z = (1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0)


def write_map(path: Path, image: np.ndarray) -> tuple[str, str]:
    """*image* ``(H, W, 3)`` written as an OpenEXR map; its path and SHA-256."""
    mi = import_mitsuba()
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    mi.Bitmap(np.ascontiguousarray(image, np.float32)).write(str(path))
    return str(path), hashlib.sha256(path.read_bytes()).hexdigest()
