"""The colour-shade cases of neighbouring pixels and the regions they join (thesis sec. 3.3.2).

Case A: the two pixels lie on different ridges; Case B: on one ridge, the step between their
colours not parallel to it; Case C: on one ridge and parallel within ``thr`` ("the paradigmatic
case of two pixels belonging to the same reflectance object but with different shadings",
sec. 3.3.2). :func:`edge_cases` classifies the MRF's edges, which then weigh ``alpha``,
``beta`` or ``gamma`` in Eq. 3.7.

**Shading boundaries merged** (:func:`merge_shading_boundaries`). The MRF of Eq. 3.4 keeps a
patch of one name wherever the unary term outweighs the pairwise term along its boundary: a
patch of area ``A`` and perimeter ``P`` whose pixels observe another name merges only when
``(1 - mu) w P > mu A`` (label distance 1), so a wide cast shadow named grey or brown on a white
or orange paint stays a region of its own, whatever the ridges say, and the global coherence
step (Eq. 3.9) then copies the shadow's edge into the reflectance. The thesis' intent is the
opposite: the colour-shade descriptor "prevents efficiently the excessive segmentation of
color names in shaded and near highlight areas" (sec. 3.2.3). So the areas of uniform
reflectance ``U_i`` of sec. 3.4 are built in two steps: the connected areas of one label (and
one ridge), then any two touching areas whose shared boundary is *mostly* Case C (more than
half of its 4-neighbour edges) are one area. A boundary where the colour changes across the
ridge (Case B) or between ridges (Case A) stays a reflectance edge. The rule has no parameter
of its own ("mostly" is a majority of the boundary's edges).
"""

from __future__ import annotations

import numpy as np

__all__ = ["CASE_A", "CASE_B", "CASE_C", "edge_cases", "merge_shading_boundaries"]

#: Edge classes of sec. 3.3.2, the values of :func:`edge_cases`.
CASE_A, CASE_B, CASE_C = 0, 1, 2


def edge_cases(
    edges: np.ndarray,
    colours: np.ndarray,
    ridge: np.ndarray,
    tangent: np.ndarray,
    threshold_deg: float,
) -> np.ndarray:
    """``(E,)`` int8 case (:data:`CASE_A`, :data:`CASE_B`, :data:`CASE_C`) of each edge.

    Parameters
    ----------
    edges
        ``(E, 2)`` indices into the colours of neighbouring pixels.
    colours
        ``(N, 3)`` the colours the ridges describe (log colours in the thesis).
    ridge, tangent
        ``(N,)`` ridge id ``SD(p)`` and ``(N, 3)`` unit ridge tangent at ``pi(p)`` of each colour
        (:class:`spectrinsic.decompose.methods.ridges.ColourShades`).
    threshold_deg
        ``thr``: steps within this angle (degrees) of the ridge are parallel; identical colours
        count as parallel.
    """
    i, j = edges[:, 0], edges[:, 1]
    same = ridge[i] == ridge[j]
    step = colours[j] - colours[i]
    length = np.linalg.norm(step, axis=1)
    along = np.abs((step * tangent[i]).sum(axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        cos_theta = np.where(length > 0.0, along / np.where(length > 0.0, length, 1.0), 1.0)
    parallel = cos_theta >= np.cos(np.radians(threshold_deg))
    return np.where(same, np.where(parallel, CASE_C, CASE_B), CASE_A).astype(np.int8)


def merge_shading_boundaries(
    regions: np.ndarray, edges: np.ndarray, parallel: np.ndarray
) -> np.ndarray:
    """Regions joined across boundaries that are mostly Case C (module docstring).

    Parameters
    ----------
    regions
        ``(H, W)`` int region index ``1..R``, 0 outside the mask.
    edges
        ``(E, 2)`` flat pixel indices (into ``regions.ravel()``) of the 4-neighbour edges
        between masked pixels.
    parallel
        ``(E,)`` bool, the edge is Case C.

    Returns
    -------
    ``(H, W)`` int64 regions ``1..R'`` (``R' <= R``), 0 outside the mask; each input region lies
    in exactly one output region.

    >>> regions = np.array([[1, 1, 2, 2]])
    >>> edges = np.array([[0, 1], [1, 2], [2, 3]])
    >>> merge_shading_boundaries(regions, edges, np.array([False, True, False])).tolist()
    [[1, 1, 1, 1]]
    >>> merge_shading_boundaries(regions, edges, np.array([True, False, True])).tolist()
    [[1, 1, 2, 2]]
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = int(regions.max()) + 1
    flat = regions.ravel()
    ra, rb = flat[edges[:, 0]], flat[edges[:, 1]]
    cross = ra != rb
    pair = np.minimum(ra[cross], rb[cross]).astype(np.int64) * n + np.maximum(ra, rb)[cross]
    uniq, inverse = np.unique(pair, return_inverse=True)
    total = np.bincount(inverse.ravel(), minlength=uniq.size)
    case_c = np.bincount(inverse.ravel(), weights=parallel[cross], minlength=uniq.size)
    a, b = np.divmod(uniq[2.0 * case_c > total], n)
    graph = coo_matrix((np.ones(a.size), (a, b)), shape=(n, n))
    _, group = connected_components(graph, directed=False)
    used = np.unique(group[flat[flat > 0]])
    renumber = np.zeros(int(group.max()) + 1, np.int64)
    renumber[used] = np.arange(1, used.size + 1)
    return np.where(regions > 0, renumber[group][regions], 0)
