"""Sharp, high-contrast steps between achromatic names are reflectance edges (Case A).

The colour cues of chapter 3 cannot tell a dark achromatic print on a pale achromatic surface
from a shadow over it: under the white light the thesis assumes (secs. 2.1, 3.6) both lie along
the grey diagonal of the log histogram, on one ridge that "spans colors from the lightest white
to the darker gray present in the shadowed part" (sec. 3.2.2), so every print/surface edge is
Case B or C and the MRF and the shading merge erase printed lettering, logos and barcodes.
Section 3.1 builds chapter 3 on the edge cue of chapter 2 and adds the colour cues to it ("the
exclusive use of edges ... is not sufficient"); that cue is sec. 2.2.1's Retinex regularity,
"brusque changes indicate reflectance variations while smooth variations are due to shading",
with the one exception that "occluding objects cause cast shadows", whose boundary is a
penumbra. Where the colour cues are silent (both pixels named only white, grey or black) this
module restores that cue and nothing more:

* **sharp** (:data:`SHARPNESS`): the one-pixel step of the linear luminance makes at least half
  of its change over the six pixels across the edge (``|I_q - I_p| >= |I_{q+2d} - I_{p-2d}| / 2``,
  ``d`` the edge's direction; linear, since blur and penumbrae both average light). A step
  blurred over at most 2 pixels (the lens and the sensor) gives 1/2 or more; a penumbra ramp
  of ``w >= 3`` pixels gives at most ``1/3`` on every one of its edges, its ends included; a
  line 1-4 pixels wide (a stroke of a letter, a bar of a barcode) returns to its surround and
  passes;
* **high contrast** (:func:`achromatic_contrast`): the log-luminance step is at least the
  smallest log ratio between the centres of neighbouring achromatic names (white/grey, about
  3.7, :func:`spectrinsic.decompose.methods.colour_naming.label_centroids`): a whole name in
  one pixel. Derived from the naming model, not fitted on any benchmark;
* **between achromatic names**: both pixels are named white, grey and black only, with a
  different leading term (white beside grey or black, grey beside black).

Such an edge is Case A (Fig. 3.6(b), "no continuity is expected between these two pixels in
the reflectance image"). A soft cast shadow keeps its Case B/C edges and stays shading; a cast
shadow with a sharp edge (an occluder touching the surface) would be taken for print, which
is the Retinex cue's own limit (sec. 2.2.1).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ...spectra.colorimetry import decode_srgb
from .colour_naming import appendix_a_labels, label_centroids
from .shade_cases import CASE_A

__all__ = [
    "SHARPNESS",
    "achromatic_contrast",
    "log_luminance",
    "sharp_contrast_edges",
    "split_sharp_achromatic",
]

#: Least share of the four-pixel change made by an edge's one-pixel step for the edge to be
#: sharp (a step blurred over at most 2 pixels; module docstring).
SHARPNESS = 0.5
#: Pixels on each side of an edge over which its change is measured.
_REACH = 2
#: Floor of luminance relative to the exposure white before the logarithm (1/255, as the
#: names-and-shades log colours).
_LOG_FLOOR = 1.0 / 255.0
#: Coordinates of black, white and grey in a colour-name vector (thesis set N order).
_ACHROMATIC = (0, 1, 10)


@lru_cache(maxsize=1)
def achromatic_contrast() -> float:
    """Least log-luminance step of a high-contrast achromatic edge: the smallest log ratio of
    the linear mean RGB of the white, grey and black label centroids (about 1.3, a factor of
    3.7: white to grey)."""
    labels = appendix_a_labels()
    pure = [int(np.flatnonzero(labels[:, k] == 1.0)[0]) for k in _ACHROMATIC]
    black, white, grey = np.log(decode_srgb(label_centroids()[pure]).mean(axis=1))
    return float(min(white - grey, grey - black))


def log_luminance(image: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``(H, W)`` natural log of the mean of the channels of *image* divided by its exposure
    white (99th percentile of the masked mean), floored at 1/255 of it."""
    lum = np.asarray(image, np.float64).mean(axis=2)
    white = float(np.percentile(lum[mask], 99.0)) if mask.any() else 1.0
    return np.log(np.maximum(lum / (white if white > 0.0 else 1.0), _LOG_FLOOR))


def sharp_contrast_edges(log_lum: np.ndarray, flat: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``(E,)`` bool: the edge is sharp and of high contrast (module docstring).

    Parameters
    ----------
    log_lum
        ``(H, W)`` log luminance (:func:`log_luminance`).
    flat
        ``(E, 2)`` flat pixel indices of 4-neighbour edges, first < second
        (:func:`spectrinsic.decompose.methods.coherence.grid_edges`).
    mask
        ``(H, W)`` bool; the outer pixels stop at the mask's and the image's border.

    >>> row = np.log(np.array([[0.8, 0.8, 0.05, 0.05, 0.8, 0.8, 0.6, 0.4, 0.2, 0.05, 0.05]]))
    >>> flat = np.array([[i, i + 1] for i in range(10)])
    >>> sharp_contrast_edges(row, flat, np.ones(row.shape, bool)).astype(int).tolist()
    [0, 1, 0, 1, 0, 0, 0, 0, 0, 0]
    """
    a, b = flat[:, 0], flat[:, 1]
    step = b - a
    before, after = _reach(a, -step, mask), _reach(b, step, mask)
    values = log_lum.ravel()
    linear = np.exp(values)
    one = np.abs(linear[b] - linear[a])
    across = np.abs(linear[after] - linear[before])
    contrast = np.abs(values[b] - values[a])
    return (one >= SHARPNESS * across) & (contrast >= achromatic_contrast())


def _reach(start: np.ndarray, step: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Flat index :data:`_REACH` pixels from *start* along *step* (+-1 or +-W), stopping at the
    last pixel inside the mask and the image."""
    h, w = mask.shape
    inside = mask.ravel()
    horizontal = np.abs(step) == 1
    here = start.copy()
    for _ in range(_REACH):
        there = here + step
        in_image = np.where(horizontal, there // w == here // w, (there >= 0) & (there < h * w))
        ok = in_image & inside[np.clip(there, 0, h * w - 1)]
        here = np.where(ok, there, here)
    return here


def split_sharp_achromatic(
    cases: np.ndarray, edges: np.ndarray, names: np.ndarray | None, strong: np.ndarray
) -> np.ndarray:
    """*cases* with every *strong* edge (:func:`sharp_contrast_edges`) between two achromatic
    names set to :data:`CASE_A`; with ``names=None`` every strong edge, whatever its names.

    Parameters
    ----------
    cases
        ``(E,)`` cases of the edges.
    edges
        ``(E, 2)`` indices into *names* of neighbouring pixels.
    names
        ``(N, 11)`` colour-name vector of each pixel (thesis set N order), or None.
    strong
        ``(E,)`` bool, the edge is sharp and of high contrast.
    """
    if names is None:
        return np.where(strong, CASE_A, cases).astype(np.int8)
    grey_terms = names[:, list(_ACHROMATIC)]
    achromatic = grey_terms.sum(axis=1) > 1.0 - 1e-9
    dominant = grey_terms.argmax(axis=1)
    i, j = edges[:, 0], edges[:, 1]
    both = achromatic[i] & achromatic[j] & (dominant[i] != dominant[j])
    return np.where(strong & both, CASE_A, cases).astype(np.int8)
