"""Choosing a decomposer's parameters by a stated protocol: hold-one-out over scenes.

Grosse et al. (ICCV 2009) chose colour Retinex's two thresholds on the MIT set by
cross-validation. Here the same is done on the rendered single-object set: the samples are
grouped by object (every lighting condition of one object is one group). For each group, the
grid point with the lowest mean score on the *other* groups is chosen and scored on the group
held out; the mean of those held-out scores estimates the error of the whole procedure. The
parameters shipped as defaults are the grid point with the lowest mean score over *all*
groups; :func:`hold_one_out` returns both.

The score of a sample is the MIT score ``(LMSE(shading_grey) + LMSE(reflectance)) / 2``
(Grosse et al.; reflectance in colour against the absolute reflectance, shading in grey against
``shading_grey``, on the evaluation mask), computed by :func:`mit_sample_score`.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import SpectrinsicError
from ...scenes.sample_id import SampleId
from ..decomposition import Decomposition
from ..metrics.scale import lmse

__all__ = [
    "Fold",
    "HoldOutResult",
    "grid_points",
    "hold_one_out",
    "mit_sample_score",
    "scene_group",
    "score_grid",
]

#: A grid point: sorted ``(parameter, value)`` pairs (hashable).
GridPoint = tuple[tuple[str, Any], ...]


def scene_group(sample_id: str) -> str:
    """The scene a sample shows: ``obj-apple`` for ``obj-apple__v0__white``
    (:meth:`spectrinsic.scenes.sample_id.SampleId.parse`; raises ``DatasetError`` for text
    that is not a sample id)."""
    return SampleId.parse(sample_id).scene


def grid_points(grid: Mapping[str, Sequence[Any]]) -> list[GridPoint]:
    """Every combination of the *grid*'s values, as sorted ``(name, value)`` tuples."""
    names = sorted(grid)
    return [
        tuple(zip(names, values, strict=True))
        for values in itertools.product(*(grid[n] for n in names))
    ]


def mit_sample_score(sample: Mapping[str, Any], mask: np.ndarray, result: Decomposition) -> float:
    """``(LMSE(shading_grey) + LMSE(reflectance)) / 2`` of one estimate (module docstring)."""
    grey = np.asarray(sample["shading_grey"], dtype=np.float64)
    refl = lmse(sample["reflectance"], result.reflectance, mask=mask)
    shad = lmse(grey, np.asarray(result.shading, dtype=np.float64).mean(axis=2), mask=mask)
    return 0.5 * (refl + shad)


def score_grid(
    samples: Iterable[tuple[str, Mapping[str, Any], np.ndarray, np.ndarray]],
    make: Callable[..., Callable[[np.ndarray, np.ndarray], Decomposition]],
    grid: Mapping[str, Sequence[Any]],
    *,
    post_grid: Mapping[str, Sequence[Any]] | None = None,
    post: Callable[..., Decomposition] | None = None,
    score: Callable[[Mapping[str, Any], np.ndarray, Decomposition], float] = mit_sample_score,
) -> dict[GridPoint, dict[str, float]]:
    """``{grid point: {sample id: score}}`` of ``make(**point)`` on each sample.

    *samples* yields ``(sample id, sample dict, input image, evaluation mask)``. Parameters in
    *post_grid* act after the decomposition: ``post(result, image, mask, **values)`` must give
    what ``make(**point, **values)`` would (e.g. the colour constancy step), so each is
    computed without decomposing again; the table's points hold both kinds of parameter.
    """
    points = grid_points(grid)
    extra = grid_points(post_grid) if post_grid else [()]
    decomposers = {p: make(**dict(p)) for p in points}
    table: dict[GridPoint, dict[str, float]] = {
        tuple(sorted(p + e)): {} for p in points for e in extra
    }
    for sid, sample, image, mask in samples:
        for p, decomposer in decomposers.items():
            result = decomposer(image, mask)
            for e in extra:
                final = post(result, image, mask, **dict(e)) if e and post else result
                table[tuple(sorted(p + e))][sid] = score(sample, mask, final)
    return table


@dataclass(frozen=True)
class Fold:
    """One held-out group: the parameters chosen without it and its mean score with them."""

    held_out: str
    chosen: GridPoint
    score: float


@dataclass(frozen=True)
class HoldOutResult:
    """Outcome of :func:`hold_one_out`.

    Attributes
    ----------
    chosen
        The grid point with the lowest mean score over all groups (the shipped default).
    chosen_score
        Its mean score over all groups (optimistic: chosen on the same data).
    folds
        Per held-out group, the point chosen on the others and its held-out score.
    held_out_score
        Mean of the folds' scores: the protocol's estimate of the error on a new object.
    """

    chosen: GridPoint
    chosen_score: float
    folds: tuple[Fold, ...]
    held_out_score: float


def _group_means(scores: Mapping[str, float], groups: Mapping[str, str]) -> dict[str, float]:
    by: dict[str, list[float]] = {}
    for sid, v in scores.items():
        by.setdefault(groups[sid], []).append(v)
    return {g: float(np.mean(v)) for g, v in by.items()}


def hold_one_out(
    table: Mapping[GridPoint, Mapping[str, float]],
    groups: Mapping[str, str],
    eligible: Callable[[GridPoint, Sequence[str]], bool] | None = None,
) -> HoldOutResult:
    """Hold-one-group-out choice of a grid point (module docstring).

    Each group weighs the same whatever its number of samples. Ties go to the first point in
    *table*'s order. Non-finite scores count as infinitely bad, and so does a point for which
    ``eligible(point, groups_chosen_on)`` is false (a constraint applied alike in every fold
    and in the final choice, e.g. "loses to a baseline on at most 2 objects").

    Raises :class:`SpectrinsicError` with fewer than two groups.
    """
    means = {p: _group_means(scores, groups) for p, scores in table.items()}
    names = sorted({g for m in means.values() for g in m})
    if len(names) < 2:
        raise SpectrinsicError(f"hold-one-out needs at least 2 scene groups; got {names}")

    def best(keep: Sequence[str]) -> tuple[GridPoint, float]:
        def cost(p: GridPoint) -> float:
            if eligible is not None and not eligible(p, keep):
                return float("inf")
            v = float(np.mean([means[p][g] for g in keep]))
            return v if np.isfinite(v) else float("inf")

        point = min(means, key=cost)
        return point, cost(point)

    folds = []
    for g in names:
        point, _ = best([n for n in names if n != g])
        folds.append(Fold(g, point, means[point][g]))
    chosen, score = best(names)
    return HoldOutResult(chosen, score, tuple(folds), float(np.mean([f.score for f in folds])))
