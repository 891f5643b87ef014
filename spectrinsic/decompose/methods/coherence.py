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
    regions: np.ndarray, region_intensity: np.ndarray, image_intensity: np.ndarray
) -> np.ndarray:
    """Per-region reflectance scales of thesis sec. 3.4 (Eqs. 3.8-3.10).

    Minimises ``sum_{i<j} l_ij (lambda_i L_i L_j^orig - lambda_j L_j L_i^orig)^2 / m_ij^2`` subject
    to ``lambda >= 1``, where ``l_ij`` counts the pixels of both regions that touch the other
    (4-neighbourhood), ``L^orig`` is the mean image intensity of those boundary pixels on each
    side, and ``m_ij`` the mean of the two products (scale normalisation).

    Parameters
    ----------
    regions
        ``(H, W)`` int region index ``1..R``, 0 outside the mask.
    region_intensity
        ``(R + 1,)`` intensity ``L_i`` of each region's reflectance colour (entry 0 unused).
    image_intensity
        ``(H, W)`` intensity of the input image.

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
    # (own region, other region, pixel): each boundary pixel once per neighbouring region.
    own = np.concatenate([ra, rb])
    other = np.concatenate([rb, ra])
    pixel = np.concatenate([pa, pb])
    key = np.unique(np.stack([own, other, pixel], axis=1), axis=0)
    pair_id = key[:, 0] * n + key[:, 1]
    uniq, inverse, counts = np.unique(pair_id, return_inverse=True, return_counts=True)
    mean_int = np.bincount(inverse, weights=flat_intensity[key[:, 2]]) / counts
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
