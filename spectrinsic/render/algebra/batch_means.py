"""Independent batches of one scene's render: their seeds, their mean and their spread, as
arithmetic on the batches' arrays (no render here: :mod:`~spectrinsic.render.batches` runs them).

The batches differ only in their seed (:func:`batch_seeds`), so the spread between them is a
direct estimate of the Monte Carlo error of their mean (:func:`relative_standard_error`,
:func:`image_noise`); :func:`batch_mean` and :func:`merge_batches` give the mean in float32,
summed in float64 in batch order; :func:`merge_owned_batches` gives the same bits, written over
the first batch's arrays where it can (a caller that drops the batches holds no third copy).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ...errors import RenderError, SceneError
from ...rng import seed_from_key
from ..result import RenderResult

__all__ = [
    "batch_counts",
    "batch_mean",
    "batch_seeds",
    "relative_standard_error",
    "image_noise",
    "merge_batches",
    "merge_owned_batches",
]


def batch_seeds(seed: int, batches: int) -> list[int]:
    """Sampler seeds of *batches* independent batches: the sample's own seed first (so one
    batch is exactly :func:`render_scene`), then seeds derived from it by key."""
    if isinstance(batches, bool) or not isinstance(batches, int) or batches < 1:
        raise SceneError(f"batches {batches!r}: expected a positive integer")
    return [int(seed)] + [seed_from_key(int(seed), f"batch-{b}") for b in range(1, batches)]


def batch_counts(seeds: Sequence[int], batch_spp: int) -> dict[str, int | list[int]]:
    """The count keys of a render's ``meta`` for batches of *batch_spp* samples per pixel with
    *seeds*: ``seed`` (the first), ``spp`` (the total) and, with several batches, ``batches``,
    ``batch_spp`` (one batch's) and ``batch_seeds``; one home for merged and relit renders."""
    n = len(seeds)
    counts: dict[str, int | list[int]] = {"seed": int(seeds[0]), "spp": batch_spp * n}
    if n > 1:
        counts.update(batches=n, batch_spp=batch_spp, batch_seeds=list(seeds))
    return counts


def relative_standard_error(batches: Sequence[np.ndarray], valid: np.ndarray) -> np.ndarray:
    """Per-pixel relative standard error of the mean of independent batch estimates.

    ``se = sqrt(Σ_b ‖x_b − x̄‖² / (B (B − 1)))`` over channels, divided by ``‖x̄‖``; 0 where
    not *valid* or where ``‖x̄‖`` is below 1e-3 of its 99th percentile (unlit).

    Parameters
    ----------
    batches
        ``B >= 2`` arrays ``(H, W, C)``, one estimate per independent batch.
    """
    stack = np.stack([np.asarray(b, np.float64) for b in batches])
    if stack.shape[0] < 2:
        raise RenderError("a noise estimate needs at least two independent batches")
    mean = stack.mean(axis=0)
    b = stack.shape[0]
    se = np.sqrt(((stack - mean) ** 2).sum(axis=(0, -1)) / (b * (b - 1)))
    norm = np.linalg.norm(mean, axis=-1)
    positive = norm[valid & (norm > 0)]
    floor = 1e-3 * np.percentile(positive, 99) if positive.size else np.inf
    ok = valid & (norm > floor)
    return np.where(ok, se / np.where(ok, norm, 1.0), 0.0)


def image_noise(results: Sequence[RenderResult]) -> float | None:
    """Median over lit pixels of the relative standard error of the mean image (XYZ of the
    31-band cube, else of the first mode), from independent batch renders; ``None`` for fewer
    than two."""
    if len(results) < 2:
        return None
    images = results[0].images
    mode = "bands31" if "bands31" in images else next(iter(images))
    stack = [np.asarray(r.images[mode], np.float64) for r in results]
    rel = relative_standard_error(stack, np.ones(stack[0].shape[:2], bool))
    return float(np.median(rel[rel > 0])) if (rel > 0).any() else 0.0


def _half_sum(a: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """``(a + b) / 2`` of two float32 arrays in float32, the bits of the float64 mean: the
    float32 sum is the float64 sum rounded once more, which is innocuous for one addition
    (53 >= 2 * 24 + 2); halving is exact, and where the half is subnormal the sum was exact
    (every float32 is a multiple of 2^-149, and one below 2^-125 has at most 24 bits).
    ``None`` where that does not hold: not both float32, or a sum beyond float32's range."""
    if not (a.dtype == b.dtype == np.float32):
        return None
    with np.errstate(over="ignore"):  # an overflow is detected below and left to float64
        half = np.add(a, b)
    half *= np.float32(0.5)
    return half if np.isfinite(half).all() else None


def batch_mean(arrays: Sequence[np.ndarray]) -> np.ndarray:
    """float32 mean of independent batch estimates, summed in order in float64 and divided by
    their number (the bits of ``np.mean(np.stack(arrays), axis=0, dtype=np.float64)``, without
    the stacked copy); one float32 array is returned as it is."""
    if len(arrays) == 1:
        return np.asarray(arrays[0], np.float32)
    if len(arrays) == 2:
        half = _half_sum(arrays[0], arrays[1])
        if half is not None:
            return half
    total = np.asarray(arrays[0], np.float64).copy()
    for array in arrays[1:]:
        total += array
    total /= len(arrays)
    return total.astype(np.float32)


def _merge_aovs(parts: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Coverage, depth and normals averaged over the batches (each batch's AOVs saw that
    batch's own pixel samples); the integer maps and the mask are those of the first batch."""
    if not parts or not parts[0]:
        return {}
    merged = dict(parts[0])
    for key in ("coverage", "depth", "normals"):
        if key in merged:
            merged[key] = batch_mean([p[key] for p in parts])
    if "normals" in merged:
        n = merged["normals"].astype(np.float64)
        length = np.linalg.norm(n, axis=-1, keepdims=True)
        merged["normals"] = np.divide(n, length, out=np.zeros_like(n), where=length > 1e-6).astype(
            np.float32
        )
    return merged


def _mean_modes(held: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Mode -> :func:`batch_mean` of one dict per batch (the modes of the first)."""
    return {m: batch_mean([h[m] for h in held]) for m in held[0]}


#: float32 elements per block of :func:`_half_into` (16 MiB of temporaries).
_HALF_BLOCK = 2**22


def _half_into(a: np.ndarray, b: np.ndarray) -> None:
    """``a[:] =`` :func:`batch_mean` ``([a, b])`` of C-contiguous float32 arrays, block by
    block: :func:`_half_sum` where its half is finite, else the float64 mean, which are the
    same bits wherever both are finite (:func:`_half_sum`), so per block is as for the whole."""
    flat_a, flat_b = a.reshape(-1), b.reshape(-1)
    for start in range(0, flat_a.size, _HALF_BLOCK):
        block = slice(start, start + _HALF_BLOCK)
        half = _half_sum(flat_a[block], flat_b[block])
        if half is None:
            half = batch_mean([flat_a[block], flat_b[block]])
        flat_a[block] = half


def _arrays(result: RenderResult) -> list[np.ndarray]:
    """Every array of *result*'s per-mode dicts and AOVs."""
    dicts = [result.images, result.raw, result.direct, result.transport, result.aovs]
    dicts += [*result.per_light, *result.parts.values(), *result.part_transport.values()]
    return [a for d in dicts for a in d.values()]


class _InPlaceMeans:
    """Means of two batches written over the first batch's arrays where that array shares
    memory with no other array of the first batch (so nothing else reads it after, and the
    raw channels that :attr:`RenderResult.batch_raw` keeps are untouched); others get a new one."""

    def __init__(self, first: RenderResult) -> None:
        arrays = _arrays(first)
        self._exclusive = {
            id(a)
            for i, a in enumerate(arrays)
            if not any(np.may_share_memory(a, o) for j, o in enumerate(arrays) if j != i)
        }

    def _owned(self, a: np.ndarray, b: np.ndarray) -> bool:
        fits = a.dtype == b.dtype == np.float32 and a.shape == b.shape
        fits = fits and a.flags.c_contiguous and a.flags.writeable and b.flags.c_contiguous
        return fits and id(a) in self._exclusive and not np.may_share_memory(a, b)

    def __call__(self, held: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
        out = {}
        for m in held[0]:
            a, b = held[0][m], held[1][m]
            if self._owned(a, b):
                _half_into(a, b)
                out[m] = a
            else:
                out[m] = batch_mean([a, b])
        return out


def merge_batches(results: Sequence[RenderResult]) -> RenderResult:
    """The mean of independent batch renders of one scene, keeping each batch's raw channels."""
    return _merge(results, _mean_modes)


def merge_owned_batches(results: Sequence[RenderResult]) -> RenderResult:
    """:func:`merge_batches`, bit for bit, for a caller that drops *results* after: with two
    batches, every float32 mean except the raw channels' is written over the first batch's
    array (the mean of a large render holds no third copy of its transport); the first batch
    is left holding means."""
    if len(results) != 2:
        return merge_batches(results)
    return _merge(results, _InPlaceMeans(results[0]))


def _merge(
    results: Sequence[RenderResult],
    mean_modes: Callable[[Sequence[dict[str, np.ndarray]]], dict[str, np.ndarray]],
) -> RenderResult:
    """:func:`merge_batches` with *mean_modes* for the per-mode float32 means but the raw
    channels' (which every batch keeps)."""
    if not results:
        raise RenderError("no batches to merge")
    if len(results) == 1:
        return results[0]
    first = results[0]
    meta = dict(first.meta)
    meta.update(
        batch_counts([int(r.meta["seed"]) for r in results], int(first.meta["spp"])),
        timings={
            k: {
                "passes": sum(r.meta["timings"][k]["passes"] for r in results),
                "seconds": sum(r.meta["timings"][k]["seconds"] for r in results),
                "per_pass": [x for r in results for x in r.meta["timings"][k]["per_pass"]],
            }
            for k in first.meta["timings"]
        },
    )
    if "spectral_spp" in first.meta:
        # as spp: every count a total, every per-batch count *batch_spp (meta.json, issue 46)
        spectral = int(first.meta["spectral_spp"])
        meta.update(spectral_spp=spectral * len(results), spectral_batch_spp=spectral)
    return RenderResult(
        images=mean_modes([r.images for r in results]),
        raw=_mean_modes([r.raw for r in results]),
        per_light=tuple(
            mean_modes([r.per_light[i] for r in results]) for i in range(len(first.per_light))
        ),
        direct=mean_modes([r.direct for r in results]),
        aovs=_merge_aovs([r.aovs for r in results]),
        transport=mean_modes([r.transport for r in results]),
        parts={p: mean_modes([r.parts[p] for r in results]) for p in first.parts},
        part_transport={
            p: mean_modes([r.part_transport[p] for r in results]) for p in first.part_transport
        },
        meta=meta,
        batch_raw=tuple(dict(r.raw) for r in results),
    )
