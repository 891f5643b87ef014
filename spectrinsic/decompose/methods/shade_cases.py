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

**A pale achromatic name beside a chromatic one** (:func:`split_pale_from_chromatic`). The
thesis assumes a white light (secs. 2.1, 3.6): shading "affects the intensity of the
reflectances in the scene but not their chromaticity", and the naming model follows it on an
achromatic surface, whose ridge "spans colors from the lightest white to the darker gray
present in the shadowed part" (sec. 3.2.2, Fig. 3.3). A step between a pixel named only white
or grey and a neighbour whose name has a chromatic term is therefore not a shading step of one
surface, even where the two colours lie on one ridge along its direction (a faint, darker print
on white paper: in the log histogram it is a step along the paper's ridge, Case C, and the MRF
erases its 1-2 pixel lines). Such an edge is Case A, the case of Fig. 3.6(b), "no continuity is
expected between these two pixels in the reflectance image". Black is left out: a coloured
paint shaded towards black is named black, which the white light does allow. No parameter.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "CASE_A",
    "CASE_B",
    "CASE_C",
    "edge_cases",
    "merge_shading_boundaries",
    "split_pale_from_chromatic",
]

#: Edge classes of sec. 3.3.2, the values of :func:`edge_cases`.
CASE_A, CASE_B, CASE_C = 0, 1, 2
#: Coordinates of the pale achromatic terms (white, grey) and of black in a colour-name
#: vector (thesis set N, :data:`spectrinsic.decompose.methods.colour_naming.COLOUR_NAMES`).
_WHITE, _GREY, _BLACK = 1, 10, 0


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


def split_pale_from_chromatic(
    cases: np.ndarray, edges: np.ndarray, names: np.ndarray
) -> np.ndarray:
    """*cases* with every edge between a pale achromatic name and a chromatic one set to
    :data:`CASE_A` (module docstring).

    Parameters
    ----------
    cases
        ``(E,)`` cases of the edges (:func:`edge_cases`).
    edges
        ``(E, 2)`` indices into *names* of neighbouring pixels.
    names
        ``(N, 11)`` colour-name vector of each pixel (memberships, thesis set N order).

    >>> white, grey_blue = np.eye(11)[1], 0.5 * (np.eye(11)[10] + np.eye(11)[5])
    >>> names = np.stack([white, grey_blue, np.eye(11)[0]])
    >>> split_pale_from_chromatic(np.array([2, 2]), np.array([[0, 1], [1, 2]]), names).tolist()
    [0, 2]
    """
    pale = names[:, _WHITE] + names[:, _GREY] > 1.0 - 1e-9
    chromatic = names.sum(axis=1) - names[:, [_WHITE, _GREY, _BLACK]].sum(axis=1) > 1e-9
    i, j = edges[:, 0], edges[:, 1]
    across = (pale[i] & chromatic[j]) | (pale[j] & chromatic[i])
    return np.where(across, CASE_A, cases).astype(np.int8)
