"""Independent batches of one scene's render, run: the one batch loop (:func:`run_batches`).
Inside a batch every mode shares seed and paths (:func:`~spectrinsic.render.scene_render.render_scene`);
the batches' seeds, mean and spread are :mod:`~spectrinsic.render.algebra.batch_means`'."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TypeVar

from ..scenes.model import Scene
from .algebra.batch_means import batch_seeds, image_noise, merge_batches, merge_owned_batches
from .base.one_pass import PassProgress
from .result import RenderResult
from .scene_render import render_scene
from .settings import RenderSettings

#: What one batch gives: a :class:`RenderResult`, or a pair holding one (the transport's).
Batch = TypeVar("Batch")

__all__ = ["run_batches", "render_batches"]


def render_batches(
    scene: Scene,
    settings: RenderSettings,
    *,
    seed: int,
    progress: PassProgress | None = None,
    data_dir: str | None = None,
) -> RenderResult:
    """:func:`render_scene` as ``settings.batches`` independent batches (module docstring),
    merged; with ``settings.noise_target``, adaptively (:func:`run_batches`). The batches are
    dropped after, so the mean is written over the first's arrays (:func:`merge_owned_batches`)."""

    def one(s: int) -> RenderResult:
        return render_scene(scene, settings, seed=s, progress=progress, data_dir=data_dir)

    return run_batches(settings, seed, one, lambda result: result, merge_owned_batches)[1]


def run_batches(
    settings: RenderSettings,
    seed: int,
    one: Callable[[int], Batch],
    result_of: Callable[[Batch], RenderResult],
    merge: Callable[[Sequence[RenderResult]], RenderResult] = merge_batches,
) -> tuple[list[Batch], RenderResult, list[int]]:
    """The one batch loop: ``one(seed)`` for the ``settings.batches`` seeds of
    :func:`batch_seeds`, then, with ``settings.noise_target``, one batch at a time while the
    median relative standard error of the images (:func:`image_noise` of ``result_of`` each
    batch) is above the target, up to ``settings.max_batches`` (default ``4 * batches``).

    Returns the batches, their *merge* (:func:`merge_batches`; ``meta["noise_target"]``: the target,
    the median reached and the cap) and the seeds used.
    """
    batches, noise_target = settings.batches, settings.noise_target
    cap = max(batches, settings.max_batches if settings.max_batches is not None else 4 * batches)
    seeds = batch_seeds(seed, cap if noise_target is not None else batches)
    done = [one(s) for s in seeds[:batches]]
    if noise_target is None:
        return done, merge([result_of(d) for d in done]), seeds
    reached = image_noise([result_of(d) for d in done])
    while reached is not None and reached > noise_target and len(done) < cap:
        done.append(one(seeds[len(done)]))
        reached = image_noise([result_of(d) for d in done])
    merged = merge([result_of(d) for d in done])
    merged.meta["noise_target"] = {
        "target": float(noise_target),
        "reached": reached,
        "max_batches": cap,
    }
    return done, merged, seeds[: len(done)]
