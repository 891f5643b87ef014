"""The working colour space of a ``.blend`` file: its colours as linear Rec. 709.

Every colour a ``.blend`` stores (a Base Color, a glass tint, a World's background colour) is
a scene-linear RGB in the file's *working colour space*: Blender 5's per-file setting
(``bpy.data.colorspace.working_space``: Linear Rec.709, the default, Linear Rec.2020 or
ACEScg); before Blender 5 always Linear Rec. 709. This project's colour route is linear
Rec. 709 (``rgb:`` and ``rgblight:``, :mod:`spectrinsic.spectra.user_spectra`), so
:func:`rec709_colour` converts a colour of another working space exactly, by colour-science's
``matrix_RGB_to_RGB`` between the two spaces' primaries and whites (Bradford adaptation from
ACEScg's white to D65, as Blender's OpenColorIO configuration converts). Blender's own
conversion (``wm.set_working_color_space`` with ``convert_colors``) agrees within 4e-6
(``docs/blender-colours.md``). A converted colour outside [0, 1] (a saturated Rec. 2020
colour outside Rec. 709) is refused where it is checked, as any colour is.

Values read raw in the working space (a ``Non-Color`` image: data, not colour) are not
converted: :func:`check_raw_values` refuses them in a file of another working space.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np

from ..errors import SceneError

__all__ = ["WORKING_SPACE", "BLENDER_SPACES", "working_space", "rec709_colour", "check_raw_values"]

#: The working space of this project's colours (Blender 5's default).
WORKING_SPACE = "Linear Rec.709"
#: Blender's working spaces and colour-science's names of them.
BLENDER_SPACES = {
    "Linear Rec.709": "ITU-R BT.709",
    "Linear Rec.2020": "ITU-R BT.2020",
    "ACEScg": "ACEScg",
}


def working_space(where: str) -> str:
    """The working space of the open ``.blend`` (the running ``bpy`` session's data): one of
    :data:`BLENDER_SPACES`, else a one-line :class:`SceneError` naming *where*."""
    import bpy

    space = str(getattr(getattr(bpy.data, "colorspace", None), "working_space", WORKING_SPACE))
    if space not in BLENDER_SPACES:
        raise SceneError(
            f"{where}: the file's working colour space is {space!r}; expected one of "
            f"{', '.join(BLENDER_SPACES)}"
        )
    return space


@functools.cache
def _to_rec709(space: str) -> np.ndarray:
    """``(3, 3)`` matrix from Blender working space *space* to linear Rec. 709."""
    import colour

    spaces = colour.RGB_COLOURSPACES
    return np.asarray(
        colour.matrix_RGB_to_RGB(
            spaces[BLENDER_SPACES[space]],
            spaces[BLENDER_SPACES[WORKING_SPACE]],
            chromatic_adaptation_transform="Bradford",
        ),
        dtype=np.float64,
    )


def rec709_colour(rgb: Sequence[float], where: str) -> tuple[float, float, float]:
    """The first three values of *rgb*, a colour in the open file's working space, in linear
    Rec. 709: as they are in a Rec. 709 file, else converted (module docstring) and rounded to
    9 significant digits (so a white stays exactly white)."""
    values = [float(c) for c in list(rgb)[:3]]
    space = working_space(where)
    if space == WORKING_SPACE:
        return values[0], values[1], values[2]
    r, g, b = (float(f"{c:.9g}") for c in _to_rec709(space) @ np.asarray(values))
    return r, g, b


def check_raw_values(where: str) -> None:
    """Refuse, in one line naming *where*, values read raw (module docstring) in a file whose
    working space is not :data:`WORKING_SPACE`."""
    space = working_space(where)
    if space != WORKING_SPACE:
        raise SceneError(
            f"{where}: Non-Color values in a file whose working colour space is {space!r}; "
            f"expected {WORKING_SPACE!r} (they would be read in the wrong primaries) or a "
            "colour image (sRGB, Linear Rec.709)"
        )
