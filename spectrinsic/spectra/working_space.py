"""The RGB working space of the ground-truth layers: one frozen record per space, from
colour-science's ``RGB_COLOURSPACES``.

Every RGB layer of a sample (``image``, ``reflectance``, ``shading``, ``residual``,
``illuminant``, ``specular``) is ``from_xyz @ XYZ``; the shading is divided by :attr:`white`,
the space's response to the perfect white under D65 at unit luminance, so D65 light is
``(1, 1, 1)``, and a reflectance is the space's colour of the surface under D65 (the perfect
white is :attr:`white`: ``(1, 1, 1)`` to 1e-4 in sRGB, ``(0.978, 1.003, 1.079)`` in ACEScg).

The default, ``acescg`` with the shading's negative components kept, was chosen by measurement
(docs/spectral-layers.md, ``make bench`` module ``residual``): over 200 generated rooms it
halves linear sRGB's residual share (median 5.98 % -> 2.37 %, p95 33.7 % -> 16.4 %) and no
pixel's shading leaves its gamut. ``srgb`` is the layers before (linear sRGB, IEC 61966-2-1,
shading clipped at 0).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from ..errors import WorkingSpaceError
from .colorimetry import white_normalised_responses
from .colourspace import srgb_matrices
from .grid import COLORIMETRIC_WAVELENGTHS
from .registry import get_sensors, get_spectrum

__all__ = [
    "WORKING_SPACES",
    "DEFAULT_WORKING_SPACE",
    "WorkingSpace",
    "working_space",
    "working_space_names",
]

#: Working spaces by option name -> colour-science colourspace name.
WORKING_SPACES: dict[str, str] = {
    "acescg": "ACEScg",
    "srgb": "sRGB",
    "rec2020": "ITU-R BT.2020",
}
#: The default working space (``--working-space``).
DEFAULT_WORKING_SPACE = "acescg"
#: Spaces whose shading is clipped at 0 (the layers of before; the clip moves out-of-gamut
#: light into the residual). The others keep negative shading components.
_CLIPPED = frozenset({"srgb"})


@dataclass(frozen=True)
class WorkingSpace:
    """One linear RGB working space.

    Attributes
    ----------
    name
        Option name (``"acescg"``, ``"srgb"``, ``"rec2020"``).
    colourspace
        colour-science's name of the space (``"ACEScg"``).
    from_xyz, to_xyz
        ``(3, 3)`` float64 matrices CIE 1931 XYZ -> linear RGB (colour-science's) and back
        (its exact inverse; sRGB: IEC 61966-2-1's pair). No chromatic adaptation: the RGB
        values are the space's own.
    to_srgb
        ``(3, 3)`` linear RGB of this space -> linear sRGB (``M_sRGB · to_xyz``; the
        identity for sRGB).
    white
        ``(3,)`` the space's colour of the perfect white under D65 at unit luminance Y = 1:
        the shading's white normalisation.
    clip_shading
        Whether the shading is clipped at 0 (``srgb`` only).
    """

    name: str
    colourspace: str
    from_xyz: np.ndarray = field(repr=False, compare=False)  # set by the name
    to_xyz: np.ndarray = field(repr=False, compare=False)  # set by the name
    to_srgb: np.ndarray = field(repr=False, compare=False)  # set by the name
    white: np.ndarray = field(repr=False, compare=False)  # set by the name
    clip_shading: bool

    def rgb(self, xyz: np.ndarray) -> np.ndarray:
        """CIE XYZ ``(..., 3)`` -> linear RGB of this space ``(..., 3)`` float64 (einsum, so
        the bits do not depend on the BLAS kernel)."""
        return np.einsum("...j,kj->...k", np.asarray(xyz, np.float64), self.from_xyz)

    def srgb(self, rgb: np.ndarray) -> np.ndarray:
        """Linear RGB of this space ``(..., 3)`` -> linear sRGB ``(..., 3)`` float64."""
        return np.einsum("...j,kj->...k", np.asarray(rgb, np.float64), self.to_srgb)

    def record(self) -> dict[str, object]:
        """The JSON record ``meta.json["working_space"]`` holds."""
        return {
            "name": self.name,
            "colourspace": self.colourspace,
            "xyz_to_rgb": self.from_xyz.tolist(),
            "rgb_to_xyz": self.to_xyz.tolist(),
            "rgb_to_srgb": self.to_srgb.tolist(),
            "white_d65": self.white.tolist(),
            "shading_clipped": self.clip_shading,
        }


def working_space_names() -> list[str]:
    """The option names, sorted: ``['acescg', 'rec2020', 'srgb']``."""
    return sorted(WORKING_SPACES)


def _d65_white(from_xyz: np.ndarray) -> np.ndarray:
    """The space's colour of the perfect white under D65 at Y = 1, on the 1 nm CIE grid, by
    the space's curves ``from_xyz · [x̄ ȳ z̄]`` (for sRGB, bit for bit the white of before)."""
    wl = COLORIMETRIC_WAVELENGTHS
    curves = np.einsum("kj,jw->kw", from_xyz, get_sensors("cie1931").on(wl))
    return white_normalised_responses(np.ones(wl.size), get_spectrum("cie:D65").on(wl), curves, wl)


def working_space(name: str, source: str = "working space") -> WorkingSpace:
    """The :class:`WorkingSpace` of an option name (computed once): the one place a name is
    checked. :class:`~spectrinsic.errors.WorkingSpaceError` naming *source* (where the name
    came from: ``"--working-space"``, ``"meta.json working_space"``) and the choices for an
    unknown one.

    >>> ws = working_space("srgb")
    >>> ws.colourspace, ws.clip_shading, bool(abs(ws.white - 1).max() < 1e-3)
    ('sRGB', True, True)
    """
    if not isinstance(name, str) or name not in WORKING_SPACES:
        raise WorkingSpaceError(f"{source} {name!r}; expected one of {working_space_names()}")
    return _working_space(name)


@functools.cache
def _working_space(name: str) -> WorkingSpace:
    if name == "srgb":
        from_xyz, to_xyz = (np.array(m, np.float64) for m in srgb_matrices())
    else:
        import colour  # noqa: PLC0415 - heavy; only here

        # the exact inverse, not colour-science's published RGB -> XYZ (rounded: their
        # product is the identity to 4e-5 only), so the sRGB view is exact
        from_xyz = np.array(colour.RGB_COLOURSPACES[WORKING_SPACES[name]].matrix_XYZ_to_RGB)
        to_xyz = np.linalg.inv(from_xyz)
    to_srgb = np.eye(3) if name == "srgb" else np.asarray(srgb_matrices()[0]) @ to_xyz
    white = np.asarray(_d65_white(from_xyz), np.float64)
    for matrix in (from_xyz, to_xyz, to_srgb, white):
        matrix.flags.writeable = False
    return WorkingSpace(
        name, WORKING_SPACES[name], from_xyz, to_xyz, to_srgb, white, name in _CLIPPED
    )
