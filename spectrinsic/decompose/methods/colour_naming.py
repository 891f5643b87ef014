"""Colour naming over the 11 basic terms (Benavente et al. 2008) and its discrete label set.

The colour-name descriptor of thesis section 3.2.1 (Eq. 3.2) gives each pixel an 11-vector of
memberships to the basic colour terms of Berlin and Kay, from the parametric fuzzy model of
Benavente, Vanrell & Baldrich, *J. Opt. Soc. Am. A* 25(10):2582-2593, 2008 ("triple sigmoid with
elliptic centre"). Appendix A discretises such vectors to at most three non-zero coordinates in
{0.25, 0.5, 0.75, 1} summing to 1: 671 labels. Section 3.3.3 maps a label back to RGB as the centre
of mass of the region of the RGB cube that the discretised descriptor sends to it.

The model's parameters ship as package data (``data/benavente2008_tse_*.csv``, see
``data/SOURCES.md``).
"""

from __future__ import annotations

import csv
import functools
import io
import itertools
from dataclasses import dataclass
from importlib import resources

import numpy as np
import numpy.typing as npt

from ...errors import SpectrinsicError

__all__ = [
    "COLOUR_NAMES",
    "TSEParameters",
    "tse_parameters",
    "srgb_to_lab",
    "colour_name_memberships",
    "colour_names",
    "appendix_a_labels",
    "discretise_memberships",
    "label_centroids",
    "observed_labels",
]

#: The 11 basic colour terms, in the order of the thesis' set N (section 3.2.1).
COLOUR_NAMES: tuple[str, ...] = (
    "black",
    "white",
    "red",
    "green",
    "yellow",
    "blue",
    "brown",
    "purple",
    "orange",
    "pink",
    "grey",
)
_CHROMATIC = ("red", "orange", "brown", "yellow", "green", "blue", "purple", "pink")
#: Upper L* bounds of the 6 lightness levels of the model (level k: thr[k-1] < L* <= thr[k]).
_LEVEL_BOUNDS = np.array([0.0, 31.0, 42.0, 51.0, 66.0, 76.0, 150.0])
#: White of the model's CIELab conversion (D65 as the source writes it).
_LAB_WHITE_XYZ = np.array([0.9505, 1.0, 1.0891])
#: Values of the non-zero coordinates of an Appendix A label.
_QUANTA = (0.25, 0.5, 0.75, 1.0)


@dataclass(frozen=True)
class TSEParameters:
    """Parameters of the TSE colour-naming model.

    Attributes
    ----------
    chromatic
        ``(8, 6, 10)`` float64: per chromatic category (order of ``categories``) and lightness
        level 1..6, ``(tx, ty, alpha_x, alpha_y, beta_x, beta_y, beta_e, ex, ey, phi_e)``
        (angles in radians, CIELab units).
    present
        ``(8, 6)`` bool, whether the category exists at that level.
    achromatic
        ``(4, 2)`` float64 lightness sigmoids ``(t, beta)``.
    categories
        The 8 chromatic category names.
    """

    chromatic: npt.NDArray[np.float64]
    present: npt.NDArray[np.bool_]
    achromatic: npt.NDArray[np.float64]
    categories: tuple[str, ...] = _CHROMATIC


def _read_csv(name: str) -> list[dict[str, str]]:
    text = resources.files("spectrinsic.decompose").joinpath("data", name).read_text("utf-8")
    lines = [line for line in text.splitlines() if not line.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(lines))))


@functools.lru_cache(maxsize=1)
def tse_parameters() -> TSEParameters:
    """Load the Benavente et al. (2008) parameters shipped as package data (read once)."""
    chromatic = np.zeros((len(_CHROMATIC), 6, 10))
    present = np.zeros((len(_CHROMATIC), 6), dtype=bool)
    keys = ("tx", "ty", "alpha_x", "alpha_y", "beta_x", "beta_y", "beta_e", "ex", "ey", "phi_e")
    for row in _read_csv("benavente2008_tse_chromatic.csv"):
        c, level = _CHROMATIC.index(row["category"]), int(row["level"]) - 1
        chromatic[c, level] = [float(row[k]) for k in keys]
        present[c, level] = True
    achromatic = np.array(
        [[float(r["t"]), float(r["beta"])] for r in _read_csv("benavente2008_tse_achromatic.csv")]
    )
    for array in (chromatic, present, achromatic):
        array.flags.writeable = False
    return TSEParameters(chromatic=chromatic, present=present, achromatic=achromatic)


def _check_rgb(values: npt.ArrayLike, what: str) -> npt.NDArray[np.float64]:
    arr = np.asarray(values, dtype=np.float64)
    if arr.ndim < 1 or arr.shape[-1] != 3:
        raise SpectrinsicError(
            f"{what} must have a last axis of 3 (R, G, B); got shape {arr.shape}"
        )
    return arr


def srgb_to_lab(srgb: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """CIELab of sRGB-encoded values in [0, 1] (IEC 61966-2-1 decoding; white as in the model).

    Parameters
    ----------
    srgb
        ``(..., 3)`` sRGB-*encoded* (gamma) values in [0, 1]; clipped to that range.

    Returns
    -------
    ``(..., 3)`` float64 ``(L*, a*, b*)``.
    """
    import colour

    rgb = np.clip(_check_rgb(srgb, "srgb"), 0.0, 1.0)
    xyz = colour.RGB_to_XYZ(rgb, "sRGB", apply_cctf_decoding=True)
    return np.asarray(colour.XYZ_to_Lab(xyz, colour.XYZ_to_xy(_LAB_WHITE_XYZ)), dtype=np.float64)


def _sigmoid(x: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    return 0.5 * (1.0 + np.tanh(0.5 * x))  # = 1 / (1 + exp(-x)) without overflow


def colour_name_memberships(
    srgb: npt.ArrayLike, *, normalise: bool = True
) -> npt.NDArray[np.float64]:
    """Memberships of colours to the 11 basic colour terms (thesis Eq. 3.2, Benavente et al. 2008).

    Parameters
    ----------
    srgb
        ``(..., 3)`` sRGB-*encoded* values in [0, 1] (clipped).
    normalise
        Divide by the sum so that memberships sum to exactly 1 (the thesis treats them as
        probabilities). The raw model sums to at least 1 (the achromatic term fills the gap);
        near the achromatic centre some fuzzy chromatic sets overlap and the raw sum reaches
        about 1.18 on ~2 % of the sRGB cube.

    Returns
    -------
    ``(..., 11)`` float64 memberships in the order of :data:`COLOUR_NAMES`.
    """
    params = tse_parameters()
    lab = srgb_to_lab(srgb)
    shape = lab.shape[:-1]
    lab = lab.reshape(-1, 3)
    L, a, b = lab[:, 0], lab[:, 1], lab[:, 2]
    level = np.clip(np.searchsorted(_LEVEL_BOUNDS, L, side="left"), 1, 6) - 1
    p = params.chromatic[:, level, :]  # (8, N, 10)
    tx, ty, ax, ay, bx, by, be, ex, ey, phi = np.moveaxis(p, -1, 0)
    da, db = a - tx, b - ty
    s1 = _sigmoid(by * (da * np.cos(ay) + db * np.sin(ay)))
    s2 = _sigmoid(bx * (-da * np.sin(ax) + db * np.cos(ax)))
    u = da * np.cos(phi) + db * np.sin(phi)
    v = -da * np.sin(phi) + db * np.cos(phi)
    with np.errstate(divide="ignore", invalid="ignore"):
        ellipse = np.where(params.present[:, level], (u / ex) ** 2 + (v / ey) ** 2 - 1.0, 0.0)
    se = _sigmoid(be * ellipse)
    chroma = np.where(params.present[:, level], s1 * s2 * se, 0.0)  # (8, N)
    achromatic = np.maximum(0.0, 1.0 - chroma.sum(axis=0))
    (t1, b1), (t2, b2), (t3, b3), (t4, b4) = params.achromatic
    black = achromatic * _sigmoid(b1 * (L - t1))
    grey = achromatic * _sigmoid(b2 * (L - t2)) * _sigmoid(b3 * (L - t3))
    white = achromatic * _sigmoid(b4 * (L - t4))
    out = np.zeros((lab.shape[0], len(COLOUR_NAMES)))
    for name, values in zip(_CHROMATIC, chroma, strict=True):
        out[:, COLOUR_NAMES.index(name)] = values
    out[:, COLOUR_NAMES.index("black")] = black
    out[:, COLOUR_NAMES.index("grey")] = grey
    out[:, COLOUR_NAMES.index("white")] = white
    if normalise:
        out /= out.sum(axis=1, keepdims=True)
    return out.reshape(*shape, len(COLOUR_NAMES))


def colour_names(srgb: npt.ArrayLike) -> npt.NDArray[np.str_]:
    """The basic colour term of highest membership for each ``(..., 3)`` sRGB-encoded colour."""
    memberships = colour_name_memberships(srgb)
    return np.asarray(COLOUR_NAMES)[np.argmax(memberships, axis=-1)]


@functools.lru_cache(maxsize=1)
def appendix_a_labels() -> npt.NDArray[np.float64]:
    """The 671 discrete colour-name labels of thesis Appendix A.

    Every 11-vector with at most three non-zero coordinates taken from {0.25, 0.5, 0.75, 1}
    and summing to 1: 11 + 55 + 110 + 495 = 671 (Eq. A.1).

    Returns
    -------
    ``(671, 11)`` float64, read-only; single-name labels first, in :data:`COLOUR_NAMES` order.
    """
    n = len(COLOUR_NAMES)
    labels: list[np.ndarray] = []
    for k in (1, 2, 3):
        for support in itertools.combinations(range(n), k):
            for values in itertools.product(_QUANTA, repeat=k):
                if abs(sum(values) - 1.0) < 1e-9:
                    vec = np.zeros(n)
                    vec[list(support)] = values
                    labels.append(vec)
    out = np.array(labels)
    out.flags.writeable = False
    return out


def discretise_memberships(
    memberships: npt.ArrayLike, *, chunk: int = 65536
) -> npt.NDArray[np.int32]:
    """Index of the Appendix A label nearest (L1) to each membership vector.

    Uses ``|p - l|_1 = sum(p) + sum_{j in supp(l)} (|p_j - l_j| - p_j)``: only the (at most
    three) non-zero coordinates of a label enter, so the search costs ``N x 671 x 3``.

    Parameters
    ----------
    memberships
        ``(..., 11)`` non-negative vectors (e.g. from :func:`colour_name_memberships`).

    Returns
    -------
    ``(...)`` int32 indices into :func:`appendix_a_labels`.
    """
    p = np.asarray(memberships, dtype=np.float64)
    if p.ndim < 1 or p.shape[-1] != len(COLOUR_NAMES):
        raise SpectrinsicError(f"memberships must have a last axis of 11; got shape {p.shape}")
    labels = appendix_a_labels()
    order = np.argsort(-labels, axis=1, kind="stable")[:, :3]  # support first (<= 3 entries)
    values = np.take_along_axis(labels, order, axis=1)  # zeros pad labels with < 3 names
    flat = p.reshape(-1, p.shape[-1])
    out = np.empty(flat.shape[0], dtype=np.int32)
    for start in range(0, flat.shape[0], chunk):
        block = flat[start : start + chunk]
        cost = np.zeros((block.shape[0], labels.shape[0]))
        for k in range(3):
            pk = block[:, order[:, k]]  # (n, 671)
            cost += np.abs(pk - values[:, k]) - pk
        out[start : start + chunk] = np.argmin(cost, axis=1)
    return out.reshape(p.shape[:-1])


@functools.lru_cache(maxsize=4)
def label_centroids(grid: int = 33) -> npt.NDArray[np.float64]:
    """Centre of mass, in sRGB-encoded space, of the RGB-cube region of each label (sec. 3.3.3).

    The cube is sampled on a regular ``grid**3`` lattice; each sample is named, discretised
    (:func:`discretise_memberships`) and averaged per label.

    Returns
    -------
    ``(671, 3)`` float64 sRGB-encoded centroids in [0, 1], NaN for labels no sample reaches
    (read-only).
    """
    axis = np.linspace(0.0, 1.0, grid)
    cube = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    idx = discretise_memberships(colour_name_memberships(cube))
    n = appendix_a_labels().shape[0]
    counts = np.bincount(idx, minlength=n).astype(np.float64)
    sums = np.stack([np.bincount(idx, weights=cube[:, c], minlength=n) for c in range(3)], axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = sums / counts[:, None]
    out.flags.writeable = False
    return out


def observed_labels(encoded: np.ndarray, name_bits: int = 8) -> np.ndarray:
    """``(N,)`` Appendix A label of each sRGB-encoded ``(N, 3)`` colour in [0, 1], named once
    per distinct quantised colour.

    With ``name_bits = b`` the encoded values are rounded to ``2**b`` levels first (the
    thesis' images are 8-bit, ``b = 8``); ``0`` names every colour as it is.
    """
    if name_bits <= 0:
        return discretise_memberships(colour_name_memberships(encoded))
    levels = (1 << name_bits) - 1
    codes = np.rint(np.clip(encoded, 0.0, 1.0) * levels).astype(np.int64)
    packed = (codes[:, 0] * (levels + 1) + codes[:, 1]) * (levels + 1) + codes[:, 2]
    unique, inverse = np.unique(packed, return_inverse=True)
    rgb = np.stack(np.unravel_index(unique, (levels + 1,) * 3), axis=1) / levels
    return discretise_memberships(colour_name_memberships(rgb))[inverse.ravel()]
