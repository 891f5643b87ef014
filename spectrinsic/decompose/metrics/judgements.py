"""Pairwise reflectance judgements derived from ground truth, for WHDR on rendered data.

Bell et al. (2014) score a reflectance estimate against human judgements of point pairs
("which point has the darker surface?"; thesis Eqs. 2.12-2.13). A rendered sample has exact
reflectance, so spectrinsic derives the judgements itself: point pairs are drawn with an explicit
seed, across and within materials, and labelled with the same rule (Eq. 2.13) applied to the true
reflectance intensities, all with weight 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ...rng import generator
from .._validation import ImageShapeError, as_image, as_mask

__all__ = [
    "EQUAL",
    "DARKER_1",
    "DARKER_2",
    "Judgements",
    "reflectance_intensity",
    "predict_judgements",
    "sample_judgements",
]

#: Judgement codes of Eq. 2.13: ``E`` (equal), ``1`` (point 1 darker), ``2`` (point 2 darker).
EQUAL, DARKER_1, DARKER_2 = 0, 1, 2
#: Floor on intensities so that ratios stay finite (as in the IIW reference code).
_MIN_INTENSITY = 1e-10


@dataclass(frozen=True)
class Judgements:
    """Point-pair reflectance judgements.

    Attributes
    ----------
    points1, points2
        ``(N, 2)`` int64 ``(row, column)`` pixel coordinates.
    labels
        ``(N,)`` int8 codes :data:`EQUAL`, :data:`DARKER_1`, :data:`DARKER_2`.
    weights
        ``(N,)`` float64 confidence weights ``w_i`` of Eq. 2.12.
    within
        ``(N,)`` bool, True for pairs drawn inside one material.
    """

    points1: np.ndarray
    points2: np.ndarray
    labels: np.ndarray
    weights: np.ndarray
    within: np.ndarray

    def __len__(self) -> int:
        return int(self.labels.shape[0])


def reflectance_intensity(reflectance: npt.ArrayLike) -> np.ndarray:
    """``(H, W)`` reflectance intensity: the mean over channels of a linear ``(H, W[, C])`` image."""
    return as_image(reflectance, "reflectance").mean(axis=2)


def predict_judgements(
    reflectance: npt.ArrayLike,
    points1: npt.ArrayLike,
    points2: npt.ArrayLike,
    *,
    delta: float,
) -> np.ndarray:
    """Judgements a reflectance image implies for point pairs, thesis Eq. 2.13.

    ``1`` if ``R_2 / R_1 > 1 + delta``, ``2`` if ``R_1 / R_2 > 1 + delta``, else ``E`` (0).
    """
    if delta < 0:
        raise ImageShapeError(f"delta must be >= 0; got {delta}")
    intensity = np.maximum(reflectance_intensity(reflectance), _MIN_INTENSITY)
    p1, p2 = np.asarray(points1, dtype=np.int64), np.asarray(points2, dtype=np.int64)
    r1 = intensity[p1[:, 0], p1[:, 1]]
    r2 = intensity[p2[:, 0], p2[:, 1]]
    out = np.full(r1.shape, EQUAL, dtype=np.int8)
    out[r2 / r1 > 1.0 + delta] = DARKER_1
    out[r1 / r2 > 1.0 + delta] = DARKER_2
    return out


def sample_judgements(
    reflectance: npt.ArrayLike,
    *,
    seed: int | np.random.Generator,
    n_pairs: int = 1000,
    mask: npt.ArrayLike | None = None,
    material_ids: npt.ArrayLike | None = None,
    within_fraction: float = 0.5,
    delta: float = 0.10,
) -> Judgements:
    """Draw point pairs and label them from the true reflectance (Eq. 2.13 with *delta*).

    Parameters
    ----------
    reflectance
        ``(H, W[, C])`` ground-truth reflectance (linear).
    seed
        Seed or Generator; the same seed gives the same pairs.
    n_pairs
        Number of pairs to draw (fewer come back when the image cannot provide them, e.g. a
        material of a single pixel).
    mask
        ``(H, W)`` valid pixels; points are drawn where the mask holds and the reflectance
        intensity is positive.
    material_ids
        ``(H, W)`` int material ids (negative = none). With ids, ``within_fraction`` of the pairs
        join two pixels of one material and the rest two pixels of different materials; without,
        all pairs are drawn uniformly.
    within_fraction
        Share of within-material pairs, in [0, 1].
    delta
        Ratio threshold used to label the pairs.
    """
    rng = generator(seed)
    intensity = reflectance_intensity(reflectance)
    shape = intensity.shape
    valid = as_mask(mask, shape) & (intensity > 0.0)
    if material_ids is not None:
        ids = np.asarray(material_ids)
        if ids.shape != shape:
            raise ImageShapeError(f"material_ids must have shape {shape}; got {ids.shape}")
        valid &= ids >= 0
    if not 0.0 <= within_fraction <= 1.0:
        raise ImageShapeError(f"within_fraction must lie in [0, 1]; got {within_fraction}")
    flat = np.flatnonzero(valid)
    if flat.size < 2 or n_pairs < 1:
        raise ImageShapeError("sample_judgements needs at least two valid pixels and n_pairs >= 1")
    if material_ids is None:
        first = rng.choice(flat, size=n_pairs)
        second = rng.choice(flat, size=n_pairs)
        within = np.zeros(n_pairs, dtype=bool)
    else:
        labels = ids.ravel()[flat]
        n_within = int(round(within_fraction * n_pairs))
        first_w, second_w = _within_pairs(rng, flat, labels, n_within)
        first_a, second_a = _across_pairs(rng, flat, labels, n_pairs - n_within)
        first = np.concatenate([first_w, first_a])
        second = np.concatenate([second_w, second_a])
        within = np.concatenate([np.ones(first_w.size, bool), np.zeros(first_a.size, bool)])
    keep = first != second
    first, second, within = first[keep], second[keep], within[keep]
    p1 = np.stack(np.unravel_index(first, shape), axis=1)
    p2 = np.stack(np.unravel_index(second, shape), axis=1)
    labels_out = predict_judgements(reflectance, p1, p2, delta=delta)
    return Judgements(p1, p2, labels_out, np.ones(len(labels_out)), within)


def _within_pairs(rng, flat, labels, n):
    """Pairs of pixels sharing a material: a random pixel, then a random pixel of its material."""
    order = np.argsort(labels, kind="stable")
    sorted_labels = labels[order]
    uniq, start, count = np.unique(sorted_labels, return_index=True, return_counts=True)
    eligible = np.isin(labels, uniq[count > 1])
    if n == 0 or not eligible.any():
        return np.empty(0, np.int64), np.empty(0, np.int64)
    pick = rng.choice(np.flatnonzero(eligible), size=n)
    group = np.searchsorted(uniq, labels[pick])
    partner = start[group] + rng.integers(0, count[group])
    return flat[pick], flat[order[partner]]


def _across_pairs(rng, flat, labels, n):
    """Pairs of pixels of different materials (rejection sampling of uniform pairs)."""
    if n == 0 or np.unique(labels).size < 2:
        return np.empty(0, np.int64), np.empty(0, np.int64)
    firsts, seconds, have = [], [], 0
    for _ in range(64):  # each round keeps a positive fraction; 64 rounds is ample
        a = rng.integers(0, flat.size, size=2 * n)
        b = rng.integers(0, flat.size, size=2 * n)
        ok = labels[a] != labels[b]
        firsts.append(a[ok])
        seconds.append(b[ok])
        have += int(ok.sum())
        if have >= n:
            break
    a = np.concatenate(firsts)[:n]
    b = np.concatenate(seconds)[:n]
    return flat[a], flat[b]
