"""Regions of uniform label and their global coherence (thesis sec. 3.3.3-3.4, Eqs. 3.8-3.10).

The graph of the MRF (4-neighbour edges between masked pixels) and the per-region intensity
scales ``lambda_i >= 1`` that make touching regions' intensity ratios follow the image's.
"""

from __future__ import annotations

import logging

import numpy as np

__all__ = ["bounded_minimum", "global_coherence", "grid_edges"]

logger = logging.getLogger(__name__)

#: Most active-set changes tried before falling back to the iterative solver.
_MAX_ACTIVE_SET_STEPS = 200


def grid_edges(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """4-neighbour edges between masked pixels.

    Returns
    -------
    edges
        ``(E, 2)`` int32 indices into the masked pixels (raster order), first < second.
    flat
        ``(E, 2)`` int64 flat pixel indices of the same pairs.
    """
    h, w = mask.shape
    index = np.full(mask.shape, -1, dtype=np.int64)
    index[mask] = np.arange(int(mask.sum()))
    pix = np.arange(h * w).reshape(h, w)
    pairs, flats = [], []
    for a, b in (
        ((slice(0, -1), slice(None)), (slice(1, None), slice(None))),
        ((slice(None), slice(0, -1)), (slice(None), slice(1, None))),
    ):
        ok = (index[a] >= 0) & (index[b] >= 0)
        pairs.append(np.stack([index[a][ok], index[b][ok]], axis=1))
        flats.append(np.stack([pix[a][ok], pix[b][ok]], axis=1))
    return np.concatenate(pairs).astype(np.int32), np.concatenate(flats)


def global_coherence(
    regions: np.ndarray,
    region_intensity: np.ndarray,
    image_intensity: np.ndarray,
    blurred: np.ndarray | None = None,
) -> np.ndarray:
    """Per-region reflectance scales of thesis sec. 3.4 (Eqs. 3.8-3.10).

    Minimises ``sum_{i<j} l_ij (lambda_i L_i L_j^orig - lambda_j L_j L_i^orig)^2 / m_ij^2`` subject
    to ``lambda >= 1``, where ``l_ij`` counts the pixels of both regions that touch the other
    (4-neighbourhood), ``L^orig`` is the mean image intensity of those boundary pixels on each
    side, and ``m_ij`` the mean of the two products (scale normalisation).

    Across the edges marked *blurred* (sharp, high-contrast steps,
    :func:`spectrinsic.decompose.methods.sharp_edges.sharp_contrast_edges`) each side's
    boundary intensity is extrapolated from the two pixels behind it (:func:`_side_reads`):
    the optics' point spread (and any averaging of pixels, as in a downscaled image) mixes
    both reflectances into the pixels on a step, which pulls the ratio measured there towards
    1, while reading further inside would add the shading's gradient over those pixels to the
    ratio (round 6, docs/names-shades-mit.md). Elsewhere the boundary pixels are read.

    Parameters
    ----------
    regions
        ``(H, W)`` int region index ``1..R``, 0 outside the mask.
    region_intensity
        ``(R + 1,)`` intensity ``L_i`` of each region's reflectance colour (entry 0 unused).
    image_intensity
        ``(H, W)`` linear intensity of the input image.
    blurred
        ``(E,)`` bool per 4-neighbour edge of the mask ``regions > 0`` in :func:`grid_edges`
        order, or None (every boundary read where it is, as before issue 48's round 6).

    Returns
    -------
    ``(R + 1,)`` float64 scales (entry 0 is 1).
    """
    import scipy.sparse as sp

    n = int(regions.max()) + 1
    flat_regions = regions.ravel()
    flat_intensity = image_intensity.ravel()
    _, flat = grid_edges(regions > 0)
    ra, rb = flat_regions[flat[:, 0]], flat_regions[flat[:, 1]]
    cross = ra != rb
    if not cross.any():
        return np.ones(n)
    pa, pb, ra, rb = flat[cross, 0], flat[cross, 1], ra[cross], rb[cross]
    # (own region, other region, pixel): each boundary pixel once per neighbouring region;
    # its intensity is the mean over its edges to that region of what is read for it.
    own = np.concatenate([ra, rb])
    other = np.concatenate([rb, ra])
    pixel = np.concatenate([pa, pb])
    marks = None if blurred is None else blurred[cross]
    read = np.concatenate(_side_reads(regions, flat_intensity, pa, pb, marks))
    key, key_of_edge = np.unique(np.stack([own, other, pixel], axis=1), axis=0, return_inverse=True)
    key_of_edge = key_of_edge.ravel()
    edges_per_key = np.bincount(key_of_edge, minlength=key.shape[0])
    key_int = np.bincount(key_of_edge, weights=read, minlength=key.shape[0]) / edges_per_key
    pair_id = key[:, 0] * n + key[:, 1]
    uniq, inverse, counts = np.unique(pair_id, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    mean_int = np.bincount(inverse, weights=key_int) / counts
    lookup = dict(zip(uniq.tolist(), range(uniq.size), strict=True))
    rows, cols, vals = [], [], []
    eq = 0
    for pid, k in lookup.items():
        i, j = divmod(pid, n)
        if i >= j:
            continue
        back = lookup[j * n + i]
        l_ij = counts[k] + counts[back]
        a_i = region_intensity[i] * mean_int[back]  # lambda_i L_i L_j^orig
        a_j = region_intensity[j] * mean_int[k]  # lambda_j L_j L_i^orig
        m = 0.5 * (a_i + a_j)
        if m <= 0.0:
            continue
        s = np.sqrt(l_ij) / m
        rows += [eq, eq]
        cols += [i, j]
        vals += [s * a_i, -s * a_j]
        eq += 1
    if eq == 0:
        return np.ones(n)
    lam = bounded_minimum(sp.csr_matrix((vals, (rows, cols)), shape=(eq, n)))
    lam[0] = 1.0
    # The objective is flat along the common scale; report the smallest solution (min = 1).
    return lam / lam[1:].min()


def _side_reads(
    regions: np.ndarray,
    intensity: np.ndarray,
    pa: np.ndarray,
    pb: np.ndarray,
    blurred: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray]:
    """Eq. 3.8's intensity on each side of the boundary edges ``(pa, pb)`` (flat indices).

    The boundary pixels' own intensities, except across a *blurred* edge where both sides
    have two more pixels of their own region straight behind the boundary pixel: there each
    side is extrapolated linearly in log intensity from those two pixels, ``2 log I_1 -
    log I_2``, back to the boundary pixel's position. Those pixels lie outside the 1-2 px over
    which a sharp step is mixed (the blur width of
    :mod:`spectrinsic.decompose.methods.sharp_edges`), and the extrapolation cancels a
    shading gradient to first order (exactly for a light falling by a constant factor per
    pixel), so Eq. 3.8's premise, the same shading at the boundary on both sides, is kept.
    """
    read_a, read_b = intensity[pa], intensity[pb]
    if blurred is None:
        return read_a, read_b
    first_a, second_a, behind_a = _two_behind(regions, pa, pa - pb)
    first_b, second_b, behind_b = _two_behind(regions, pb, pb - pa)
    positive = intensity > 0.0  # a log needs light on both pixels behind each side
    use = blurred & behind_a & behind_b & positive[first_a] & positive[second_a]
    use &= positive[first_b] & positive[second_b]
    log_i = np.log(np.where(positive, intensity, 1.0))
    extrapolated_a = np.exp(2.0 * log_i[first_a] - log_i[second_a])
    extrapolated_b = np.exp(2.0 * log_i[first_b] - log_i[second_b])
    return np.where(use, extrapolated_a, read_a), np.where(use, extrapolated_b, read_b)


def _two_behind(
    regions: np.ndarray, start: np.ndarray, away: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Flat indices of the pixels one and two steps of *away* (``+-1`` or ``+-W``) from each
    *start* pixel, and whether both lie in the image and in the start pixel's own region."""
    h, w = regions.shape
    flat_regions = regions.ravel()
    inside = np.ones(start.shape, bool)
    behind = []
    for k in (1, 2):
        there = start + k * away
        in_image = np.where(
            np.abs(away) == 1, there // w == start // w, (there >= 0) & (there < h * w)
        )
        there = np.clip(there, 0, h * w - 1)
        inside &= in_image & (flat_regions[there] == flat_regions[start])
        behind.append(there)
    return behind[0], behind[1], inside


def bounded_minimum(a) -> np.ndarray:
    """``argmin ||A lambda||^2`` subject to ``lambda >= 1`` for a sparse ``(E, n)`` matrix *A*.

    Eq. 3.10's problem. ``Q = A^T A`` is a symmetric M-matrix here (every row of *A* is
    ``s (a_i lambda_i - a_j lambda_j)`` with ``a > 0``, so off-diagonal entries are <= 0), for
    which the primal-dual active-set method (Hintermueller, Ito & Kunisch, SIAM J. Optim.
    13(3), 2002) reaches the exact minimiser in a few sparse solves: bound set
    ``B = {i: nu_i - c (lambda_i - 1) > 0}``, ``lambda_B = 1``, ``Q_FF lambda_F = -Q_FB 1``,
    ``nu = Q lambda`` on ``B``, until ``B`` repeats (ties, ``nu = 0`` at the bound, stay bound).
    Columns without equations stay at 1. If a
    free block is singular or the sets cycle, :func:`scipy.optimize.lsq_linear` solves it
    (bounded least squares by LSMR, tolerance 1e-10; the solver used before, 10-100x slower).
    """
    import scipy.sparse as sp
    from scipy.sparse.linalg import spsolve

    q = (a.T @ a).tocsr()
    n = q.shape[0]
    used = q.diagonal() > 0.0
    lam, nu = np.ones(n), np.asarray(q @ np.ones(n)).ravel()
    c = float(q.diagonal()[used].mean()) if used.any() else 1.0
    # A multiplier that is zero at the optimum (a ratio met exactly) keeps its bound: released,
    # the free block would be singular (the objective is flat along the common scale).
    tie = 1e-12 * c
    bound = (nu - c * (lam - 1.0) > -tie) | ~used
    for _ in range(_MAX_ACTIVE_SET_STEPS):
        free = ~bound
        lam = np.ones(n)
        if free.any():
            rhs = -np.asarray(q[free][:, bound] @ np.ones(int(bound.sum()))).ravel()
            with np.errstate(all="ignore"):
                solved = np.atleast_1d(spsolve(sp.csc_matrix(q[free][:, free]), rhs))
            if not np.all(np.isfinite(solved)):
                break
            lam[free] = solved
        nu = np.where(bound, np.asarray(q @ lam).ravel(), 0.0)
        new = ((nu - c * (lam - 1.0)) > -tie) | ~used
        if np.array_equal(new, bound):
            return lam
        bound = new
    logger.debug("coherence: active set did not settle; bounded LSMR instead")
    return _bounded_lsmr(a)


def _bounded_lsmr(a) -> np.ndarray:
    from scipy.optimize import lsq_linear

    result = lsq_linear(a, np.zeros(a.shape[0]), bounds=(1.0, np.inf), lsq_solver="lsmr", tol=1e-10)
    return np.where(np.isfinite(result.x), result.x, 1.0)
