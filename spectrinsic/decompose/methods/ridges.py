"""The colour-shade descriptor: ridges of an image's colour distribution (thesis sec. 3.2.2).

Vazquez et al. (RAD: ECCV 2008, PAMI 2011) describe each surface of an image by a *ridge* of its
colour histogram: the curve joining the local maxima of the distribution, along which shading and
highlights move the colours of one surface (Shafer's dichromatic model). The descriptor of a
pixel is the ridge nearest to its colour (thesis Eq. 3.3).

Two detectors, both on an isotropic 3-D histogram of the colours (cubic bins, ``bins`` along the
widest axis):

``"rad"`` (default), RAD's three steps:

1. **Creaseness** by MLSEC-ST (Lopez et al. 1999, the measure RAD uses because gaps and small
   irregularities along a ridge do not break it): the histogram's gradient ``w`` at derivative
   scale ``sigma``; the structure tensor ``S = G_{2 sigma} * (w w^T)``; its dominant eigenvector
   ``v`` turned to the gradient's side, ``w~ = sign(v . w) v``; creaseness ``k = -div(w~)``.
   On a line ridge in 3-D the two transverse directions converge (``k`` near 2), on a blob all
   three (near 3); flanks and valleys are at or below 0.
2. **Ridge extraction**: bins with ``k >= creaseness`` and smoothed density at least
   ``min_density`` are thinned to one-bin-wide curves (:func:`skimage.morphology.skeletonize`),
   and curves connected in the 26-neighbourhood form one ridge.
   With ``max_axis_angle`` set, ridge bins whose local direction (principal axis of the ridge
   bins within ``_AXIS_RADIUS`` bins) is more than that angle from the grey diagonal are removed
   before the curves are labelled, and pieces on one line along the diagonal (mean
   chromaticities within ``_REJOIN_RADIUS`` bins) are joined again. On the histogram of *log* colours (as the thesis builds it)
   a grey shading change moves every surface's colours along the diagonal ``(1, 1, 1)``, so a
   surface's ridge runs parallel to it; a crest segment across the diagonal is a bridge
   between the ridges of two surfaces (a saddle of the density), which the threshold-and-thin
   step would otherwise join into one ridge (deer and paper1 of the MIT set,
   docs/names-shades-mit.md).
3. **Pruning**: a ridge nearest to fewer than ``min_share`` of the colours is dropped and the
   colours are assigned again (RAD keeps the ridges of the dominant colours).

``"hessian"``: the earlier pragmatic detector (a bin is a ridge point where the two most
negative Hessian eigenvalues of the smoothed histogram are negative and it is a maximum along
both transverse eigenvectors); kept for the ablation (docs/names-shades-mit.md).

Each colour is assigned the ridge of the nearest ridge bin (Euclidean distance transform of the
grid, Eq. 3.3), or, with ``flooding``, the ridge of RAD's flooding step: the histogram's bins,
taken by descending smoothed density, join the ridge of the denser neighbour they are reached
from (a watershed of ``-density`` seeded by the ridges), so each ridge owns the "dominant
structure" around it and a colour takes the ridge whose density it lies under, not the one
nearest in Euclidean distance (two surfaces' ridges converge at the dark end of the log
histogram, where a shadowed colour can be nearer another surface's ridge than its own). Its projection ``pi(p)`` is the foot of the perpendicular on the ridge's local
tangent line through that bin (``rad``: principal axis of the ridge's bins within
``tangent_radius`` bins; ``hessian``: the Hessian eigenvector of the largest eigenvalue).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .._validation import ImageShapeError

__all__ = ["RIDGE_DETECTORS", "ColourShades", "colour_shades"]

#: Ridge detectors of :func:`colour_shades`.
RIDGE_DETECTORS = ("rad", "hessian")
_DIAGONAL = np.full(3, 1.0 / np.sqrt(3.0))
#: Radius (bins) of the neighbourhood whose principal axis is a crest bin's direction when
#: ``max_axis_angle`` cuts the crest across the diagonal (the thinned curve's next bins).
_AXIS_RADIUS = 2.0
#: After the cut, pieces whose mean log chromaticity (bins projected on the plane across the
#: diagonal) is closer than this many bins are one ridge again: the cut also breaks a
#: surface's own ridge where it wiggles, and its pieces lie on one line along the diagonal.
_REJOIN_RADIUS = 1.0


@dataclass(frozen=True)
class ColourShades:
    """Colour-shade descriptor of a set of colours.

    Attributes
    ----------
    ridge
        ``(N,)`` int64 ridge id of each colour, ``SD(p)`` of Eq. 3.3 (0..n_ridges-1).
    projection
        ``(N, 3)`` float64 projection ``pi(p)`` on the ridge (same units as the input colours).
    tangent
        ``(N, 3)`` float64 unit tangent of the ridge at the projection.
    n_ridges
        Number of ridges found (at least 1).
    bin_width
        Side of a histogram bin (input units).
    ridge_points
        ``(M, 3)`` float64 the ridges' bin centres (input units), for figures (Fig. 3.3(c)).
    ridge_of_point
        ``(M,)`` int64 ridge id of each of ``ridge_points``.
    """

    ridge: np.ndarray
    projection: np.ndarray
    tangent: np.ndarray
    n_ridges: int
    bin_width: float
    ridge_points: np.ndarray
    ridge_of_point: np.ndarray


@dataclass(frozen=True)
class _Grid:
    """The colours' histogram: ``lo + (index - pad) * width`` is a bin centre (input units)."""

    hist: np.ndarray
    index: np.ndarray  # (N, 3) bin of each colour
    lo: np.ndarray
    width: float
    pad: int


def colour_shades(
    colours: npt.ArrayLike,
    *,
    bins: int = 64,
    sigma: float = 1.0,
    detector: str = "rad",
    min_density: float | None = None,
    creaseness: float = 1.0,
    min_share: float = 0.005,
    tangent_radius: float = 3.0,
    max_axis_angle: float | None = None,
    flooding: bool = False,
) -> ColourShades:
    """Find the ridges of the distribution of *colours* and describe each colour by them.

    Parameters
    ----------
    colours
        ``(N, 3)`` colours (the thesis applies a logarithm to the image first).
    bins
        Number of bins along the widest axis of the colours' bounding box (bins are cubes).
    sigma
        Gaussian smoothing (``hessian``) or derivative scale (``rad``) of the histogram, in bins.
    detector
        ``"rad"`` or ``"hessian"`` (:data:`RIDGE_DETECTORS`; module docstring).
    min_density
        Smoothed count below which a bin cannot be a ridge point; default ``max(0.5, 2e-5 N)``.
    creaseness
        ``rad``: MLSEC-ST creaseness a ridge bin reaches (dimensionless, at most 3).
    min_share
        ``rad``: fraction of the colours a ridge must be nearest to, else it is pruned.
    tangent_radius
        ``rad``: radius in bins of the ridge neighbourhood whose principal axis is the tangent.
    max_axis_angle
        ``rad``: degrees; crest bins whose local direction is further than this from the grey
        diagonal are cut out (module docstring, step 2). ``None``: no cut.
    flooding
        Each colour takes the ridge whose flooded domain holds its bin (module docstring)
        instead of the nearest ridge; its projection is on that ridge's nearest bin.
    """
    from scipy import ndimage

    x = np.asarray(colours, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3 or x.shape[0] == 0:
        raise ImageShapeError(f"colours must be a non-empty (N, 3) array; got shape {x.shape}")
    if detector not in RIDGE_DETECTORS:
        raise ValueError(f"detector must be one of {RIDGE_DETECTORS}; got {detector!r}")
    if min_density is None:
        min_density = max(0.5, 2e-5 * x.shape[0])
    grid = _histogram(x, bins, sigma)
    density = ndimage.gaussian_filter(grid.hist, sigma, mode="constant")
    if detector == "hessian":
        ridge_mask, tangent_grid = _hessian_ridges(density, min_density)
    else:
        ridge_mask = _rad_ridges(grid.hist, density, sigma, min_density, creaseness)
    if not ridge_mask.any():
        diagonal = np.broadcast_to(_DIAGONAL, x.shape).copy()
        return ColourShades(
            np.zeros(x.shape[0], np.int64),
            x.copy(),
            diagonal,
            1,
            grid.width,
            x.mean(axis=0, keepdims=True),
            np.zeros(1, np.int64),
        )
    components, _ = ndimage.label(ridge_mask, structure=np.ones((3, 3, 3)))
    if detector == "rad" and max_axis_angle is not None:
        components = _cut_across_diagonal(components, max_axis_angle)
    if detector == "rad":
        components = _prune(components, grid.index, min_share)
        tangent_grid = _local_axes(components, tangent_radius)
    domains = _flood(components, density) if flooding else None
    return _describe(x, grid, components, tangent_grid, domains)


def _histogram(x: np.ndarray, bins: int, sigma: float) -> _Grid:
    """Counts of *x* in cubic bins, padded by ``3 sigma + 1`` bins on every side."""
    lo, hi = x.min(axis=0), x.max(axis=0)
    width = float((hi - lo).max()) / max(bins - 1, 1)
    if width <= 0.0:
        width = 1.0
    pad = int(np.ceil(3.0 * sigma)) + 1
    dims = tuple(int(d) for d in np.round((hi - lo) / width).astype(int) + 1 + 2 * pad)
    idx = np.round((x - lo) / width).astype(np.int64) + pad
    flat = np.ravel_multi_index(idx.T, dims)
    hist = np.bincount(flat, minlength=int(np.prod(dims))).reshape(dims).astype(np.float64)
    return _Grid(hist, idx, lo, width, pad)


def _rad_ridges(
    hist: np.ndarray, density: np.ndarray, sigma: float, min_density: float, creaseness: float
) -> np.ndarray:
    """RAD steps 1-2: thinned bins of MLSEC-ST creaseness >= *creaseness* (module docstring)."""
    from scipy import ndimage
    from skimage.morphology import skeletonize

    orders = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    grad = np.stack(
        [ndimage.gaussian_filter(hist, sigma, order=o, mode="constant") for o in orders], axis=-1
    )
    tensor = np.empty(hist.shape + (3, 3))
    for a in range(3):
        for b in range(a, 3):
            tensor[..., a, b] = tensor[..., b, a] = ndimage.gaussian_filter(
                grad[..., a] * grad[..., b], 2.0 * sigma, mode="constant"
            )
    support = density >= min_density
    field = np.zeros(hist.shape + (3,))
    dominant = principal_axes(tensor[support], _DIAGONAL)
    g = grad[support]
    dot = (dominant * g).sum(axis=1)
    # the gradient's side of the axis; where the gradient is orthogonal to it (to rounding),
    # the axis keeps principal_axes' deterministic sign rather than the sign of rounding noise
    level = 1e-9 * np.sqrt((g * g).sum(axis=1))
    side = np.where(np.abs(dot) > level, np.sign(dot), 1.0)
    field[support] = side[:, None] * dominant
    kappa = -sum(np.gradient(field[..., k], axis=k) for k in range(3))
    # compared at 1e-9: a symmetric histogram can put kappa on the threshold, where rounding
    # in the last bits would decide
    crest = support & (np.round(kappa, 9) >= creaseness)
    return np.asarray(skeletonize(crest), dtype=bool)


def _cut_across_diagonal(components: np.ndarray, max_angle_deg: float) -> np.ndarray:
    """Step 2's cut: ridge bins whose local axis is more than *max_angle_deg* from the grey
    diagonal removed, the remaining curves labelled again (26-connected) and pieces of one
    line along the diagonal joined (``_REJOIN_RADIUS``); unchanged if the cut would remove
    every bin."""
    from scipy import ndimage
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    axes = _local_axes(components, _AXIS_RADIUS)
    along = np.abs((axes * _DIAGONAL).sum(axis=-1))  # elementwise: no BLAS kernel in the bits
    keep = (components > 0) & (along >= np.cos(np.radians(max_angle_deg)))
    if not keep.any():
        return components
    pieces, n = ndimage.label(keep, structure=np.ones((3, 3, 3)))
    points = np.argwhere(pieces > 0).astype(np.float64)
    piece = pieces[pieces > 0]
    across = points - np.outer((points * _DIAGONAL).sum(axis=1), _DIAGONAL)  # chromaticity
    count = np.bincount(piece, minlength=n + 1)[1:]
    centre = (
        np.stack(
            [np.bincount(piece, weights=across[:, k], minlength=n + 1)[1:] for k in range(3)],
            axis=1,
        )
        / count[:, None]
    )
    near = np.linalg.norm(centre[:, None, :] - centre[None, :, :], axis=2) < _REJOIN_RADIUS
    _, group = connected_components(csr_matrix(near), directed=False)
    return np.concatenate([[0], group + 1])[pieces]


def _hessian_ridges(density: np.ndarray, min_density: float) -> tuple[np.ndarray, np.ndarray]:
    """The ``hessian`` detector: ridge bins and the Hessian tangent there."""
    dims = density.shape
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
    return ridge_mask, tangent_grid


def _nearest(ridge_mask: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``(N, 3)`` the nearest ridge bin of each colour's bin (Euclidean, Eq. 3.3)."""
    from scipy import ndimage

    _, nearest = ndimage.distance_transform_edt(~ridge_mask, return_indices=True)
    return nearest[:, index[:, 0], index[:, 1], index[:, 2]].T


def _prune(components: np.ndarray, index: np.ndarray, min_share: float) -> np.ndarray:
    """RAD step 3: ridges nearest to fewer than *min_share* of the colours removed (the
    largest ridge always stays); the others renumbered 1..R."""
    near = _nearest(components > 0, index)
    owner = components[near[:, 0], near[:, 1], near[:, 2]]
    counts = np.bincount(owner, minlength=int(components.max()) + 1)[1:]
    keep = counts >= min_share * index.shape[0]
    keep[int(np.argmax(counts))] = True
    renumber = np.zeros(counts.size + 1, np.int64)
    renumber[1:][keep] = np.arange(1, int(keep.sum()) + 1)
    return renumber[components]


def principal_axes(matrices: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Unit eigenvector of the largest eigenvalue of each symmetric ``(N, 3, 3)`` matrix, the same
    whatever the LAPACK kernel: where that eigenvalue ties with the next (within 1e-9 of it, as
    in a symmetric histogram), eigh's vector inside the tied eigenspace follows the kernel
    (``OPENBLAS_CORETYPE`` changed the regions of a grey checker), so the axis is the first of
    *reference*, x, y projected onto that eigenspace that is not orthogonal to it (*reference*
    itself where all three tie); each axis is signed to point along *reference* (or, orthogonal
    to it, along the first such vector)."""
    vals, vecs = np.linalg.eigh(matrices)
    tol = 1e-9 * np.abs(vals[:, 2:3])
    top, second = vecs[:, :, 2], vecs[:, :, 1]
    ties_second = (vals[:, 2:3] - vals[:, 1:2]) <= tol
    ties_all = ties_second & ((vals[:, 2:3] - vals[:, 0:1]) <= tol)
    references = (np.asarray(reference, np.float64), np.eye(3)[0], np.eye(3)[1])
    axes = top.copy()
    chosen = ~ties_second[:, 0]
    for ref in references:
        on = (top * ref).sum(axis=1, keepdims=True) * top
        on = on + (second * ref).sum(axis=1, keepdims=True) * second
        on = np.where(ties_all, ref, on)
        length = np.sqrt((on * on).sum(axis=1, keepdims=True))
        take = ~chosen & (length[:, 0] > 1e-6)
        axes[take] = (on / np.maximum(length, 1e-300))[take]
        chosen |= take
    signed = np.zeros(len(axes), bool)
    for ref in references:  # the sign of the first reference the axis is not orthogonal to
        along = (axes * ref).sum(axis=1)
        use = ~signed & (np.abs(along) > 1e-9)
        axes[use & (along < 0)] *= -1.0
        signed |= use
    return axes


def _local_axes(components: np.ndarray, radius: float) -> np.ndarray:
    """Unit principal axis of each ridge bin's same-ridge neighbours within *radius* bins
    (the ridge's local direction); the grey diagonal where a bin has no neighbour."""
    from scipy import sparse
    from scipy.spatial import cKDTree

    points = np.argwhere(components > 0)
    ridge = components[tuple(points.T)]
    pairs = cKDTree(points).query_pairs(radius, output_type="ndarray")
    pairs = pairs[ridge[pairs[:, 0]] == ridge[pairs[:, 1]]]
    m = points.shape[0]
    rows = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(m)])
    cols = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(m)])
    adjacency = sparse.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(m, m))
    p = points.astype(np.float64)
    count = np.asarray(adjacency.sum(axis=1)).ravel()
    mean = adjacency @ p / count[:, None]
    second = adjacency @ (p[:, :, None] * p[:, None, :]).reshape(m, 9) / count[:, None]
    cov = second.reshape(m, 3, 3) - mean[:, :, None] * mean[:, None, :]
    axes = np.where((count > 1)[:, None], principal_axes(cov, _DIAGONAL), _DIAGONAL)
    tangent_grid = np.zeros(components.shape + (3,))
    tangent_grid[tuple(points.T)] = axes
    return tangent_grid


def _flood(components: np.ndarray, density: np.ndarray) -> np.ndarray:
    """RAD's flooding: every bin of the smoothed histogram's support joins a ridge, the bins
    taken by descending density and each given the ridge of the denser neighbour it is
    reached from (a watershed of ``-density`` seeded by the ridges)."""
    from skimage.segmentation import watershed

    return np.asarray(watershed(-density, markers=components, mask=density > 0.0), np.int64)


def _nearest_on(components: np.ndarray, domains: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``(N, 3)`` for each colour's bin, the nearest bin of the ridge whose domain holds it."""
    near = np.zeros((index.shape[0], 3), np.int64)
    owner = domains[index[:, 0], index[:, 1], index[:, 2]]
    for k in np.unique(owner):
        sel = owner == k
        mask = components == k if k > 0 else components > 0
        near[sel] = _nearest(mask, index[sel])
    return near


def _describe(
    x: np.ndarray,
    grid: _Grid,
    components: np.ndarray,
    tangent_grid: np.ndarray,
    domains: np.ndarray | None = None,
) -> ColourShades:
    """Eq. 3.3 on labelled ridge bins: each colour's ridge, projection and tangent."""
    ridge_mask = components > 0
    ids = np.unique(components[ridge_mask])
    renumber = np.zeros(int(components.max()) + 1, np.int64)
    renumber[ids] = np.arange(ids.size)
    if domains is None:
        near = _nearest(ridge_mask, grid.index)
    else:
        near = _nearest_on(components, domains, grid.index)
    ridge = renumber[components[near[:, 0], near[:, 1], near[:, 2]]]
    centre = grid.lo + (near - grid.pad) * grid.width
    tangent = tangent_grid[near[:, 0], near[:, 1], near[:, 2]]
    projection = centre + ((x - centre) * tangent).sum(axis=1, keepdims=True) * tangent
    points = np.argwhere(ridge_mask)
    return ColourShades(
        ridge,
        projection,
        tangent,
        int(ids.size),
        grid.width,
        grid.lo + (points - grid.pad) * grid.width,
        renumber[components[tuple(points.T)]],
    )
