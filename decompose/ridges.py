"""The colour-shade descriptor: ridges of an image's colour distribution (thesis sec. 3.2.2).

Vazquez et al. (RAD, PAMI 2011) describe each surface of an image by a *ridge* of its colour
histogram: the curve joining the local maxima of the distribution, along which shading and
highlights move the colours of one surface (Shafer's dichromatic model). The descriptor of a
pixel is the ridge nearest to its colour (Eq. 3.3).

Implementation (a pragmatic RAD): the colours are binned into an isotropic 3-D histogram and
smoothed with a Gaussian; a bin is a ridge point when the two most negative eigenvalues of the
Hessian are negative (the density is concave across the ridge) and the bin is a maximum of the
density along both transverse eigenvectors; ridge points connected in the 26-neighbourhood form
one ridge. Each colour is assigned the ridge of the nearest ridge point (Euclidean distance
transform of the histogram grid), its projection is that point, and the ridge's local tangent is
the Hessian eigenvector of the largest eigenvalue there. Distances and projections are therefore
quantised to the bin grid; RAD's creaseness filtering and ridge pruning are not reproduced.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from spectrinsic.decompose._validation import ImageShapeError

__all__ = ["ColourShades", "colour_shades"]


@dataclass(frozen=True)
class ColourShades:
    """Colour-shade descriptor of a set of colours.

    Attributes
    ----------
    ridge
        ``(N,)`` int64 ridge id of each colour, ``SD(p)`` of Eq. 3.3 (0..n_ridges-1).
    projection
        ``(N, 3)`` float64 nearest ridge point ``pi(p)`` (same units as the input colours).
    tangent
        ``(N, 3)`` float64 unit tangent of the ridge at the projection.
    n_ridges
        Number of ridges found (at least 1).
    bin_width
        Side of a histogram bin (input units).
    """

    ridge: np.ndarray
    projection: np.ndarray
    tangent: np.ndarray
    n_ridges: int
    bin_width: float


def colour_shades(
    colours: npt.ArrayLike,
    *,
    bins: int = 64,
    sigma: float = 1.0,
    min_density: float | None = None,
) -> ColourShades:
    """Find the ridges of the distribution of *colours* and describe each colour by them.

    Parameters
    ----------
    colours
        ``(N, 3)`` colours (the thesis applies a logarithm to the image first).
    bins
        Number of bins along the widest axis of the colours' bounding box (bins are cubes).
    sigma
        Gaussian smoothing of the histogram, in bins.
    min_density
        Smoothed count below which a bin cannot be a ridge point; default ``max(0.5, 2e-5 N)``.
    """
    from scipy import ndimage

    x = np.asarray(colours, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3 or x.shape[0] == 0:
        raise ImageShapeError(f"colours must be a non-empty (N, 3) array; got shape {x.shape}")
    n = x.shape[0]
    if min_density is None:
        min_density = max(0.5, 2e-5 * n)
    lo, hi = x.min(axis=0), x.max(axis=0)
    width = float((hi - lo).max()) / max(bins - 1, 1)
    if width <= 0.0:
        width = 1.0
    pad = int(np.ceil(3.0 * sigma)) + 1
    dims = tuple(int(d) for d in np.round((hi - lo) / width).astype(int) + 1 + 2 * pad)
    idx = np.round((x - lo) / width).astype(np.int64) + pad
    flat = np.ravel_multi_index(idx.T, dims)
    hist = np.bincount(flat, minlength=int(np.prod(dims))).reshape(dims).astype(np.float64)
    density = ndimage.gaussian_filter(hist, sigma, mode="constant")

    grads = np.gradient(density)
    hessian = np.empty(dims + (3, 3))
    for i in range(3):
        second = np.gradient(grads[i])
        for j in range(3):
            hessian[..., i, j] = second[j]
    hessian = 0.5 * (hessian + np.swapaxes(hessian, -1, -2))
    candidates = np.flatnonzero(density.ravel() >= min_density)
    tangent_grid = np.zeros(dims + (3,))
    ridge_mask = np.zeros(dims, dtype=bool)
    if candidates.size:
        evals, evecs = np.linalg.eigh(hessian.reshape(-1, 3, 3)[candidates])
        pos = np.stack(np.unravel_index(candidates, dims), axis=1)
        is_ridge = evals[:, 1] < 0.0
        values = density.ravel()[candidates]
        for k in (0, 1):  # the two transverse directions (most negative curvature)
            step = np.round(evecs[:, :, k]).astype(np.int64)
            for sign in (1, -1):
                nb = np.clip(pos + sign * step, 0, np.array(dims) - 1)
                is_ridge &= values >= density[nb[:, 0], nb[:, 1], nb[:, 2]]
        ridge_pos = pos[is_ridge]
        ridge_mask[tuple(ridge_pos.T)] = True
        tangent_grid[tuple(ridge_pos.T)] = evecs[is_ridge, :, 2]

    if not ridge_mask.any():
        diagonal = np.full((n, 3), 1.0 / np.sqrt(3.0))
        return ColourShades(np.zeros(n, np.int64), x.copy(), diagonal, 1, width)
    components, n_ridges = ndimage.label(ridge_mask, structure=np.ones((3, 3, 3)))
    _, nearest = ndimage.distance_transform_edt(~ridge_mask, return_indices=True)
    near = nearest[:, idx[:, 0], idx[:, 1], idx[:, 2]].T  # (N, 3) nearest ridge bin of each colour
    ridge = components[near[:, 0], near[:, 1], near[:, 2]].astype(np.int64) - 1
    projection = lo + (near - pad) * width
    tangent = tangent_grid[near[:, 0], near[:, 1], near[:, 2]]
    return ColourShades(ridge, projection, tangent, int(n_ridges), width)
