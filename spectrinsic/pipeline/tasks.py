"""The records of one sample's work: the task a worker gets, and what it gives back; the
times they add up to (Mitsuba's part of a sample, a build run's record).

Plain picklable records (no live objects), below both the planner of the library layout
(:mod:`spectrinsic.pipeline.dataset`) and that of generated scenes and scene files
(:mod:`spectrinsic.pipeline.source_plan`), which both make :class:`SampleTask` lists.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from ..gt_export.dataset.build_time import BuildRun, usable_cpus, utc_now
from ..rng import seed_from_key
from ..scenes.sample_id import SampleId
from ..scenes.sources import FileSource
from .presets import DatasetConfig

__all__ = ["SampleTask", "SampleOutcome", "SampleFailure", "mitsuba_seconds", "run_record"]


@dataclass(frozen=True)
class SampleTask:
    """Everything a worker needs to build one sample (picklable; no live objects).

    Attributes
    ----------
    id
        Which scene, camera view and lighting condition; ``str(id)`` is the sample's folder
        name (:attr:`sample_id`).
    seed
        The sample's render seed, ``seed_from_key(config.seed, sample_id)``. The scene library
        draws the lights from the root seed ``config.seed`` instead, so every view of a scene
        under one condition shares its lights.
    out_dir
        Dataset folder; the sample is written to ``out_dir/sample_id``.
    config
        The build settings.
    data_dir
        Spectral data directory, or ``None`` for ``$SPECTRINSIC_DATA``.
    render_threads
        Dr.Jit worker threads per process, or ``None`` to leave Dr.Jit's default (all cores).
    source
        A :mod:`spectrinsic.scenes.sources` record (generated scene or scene file) the worker
        builds the scene from; ``None`` for a library scene.
    """

    id: SampleId
    seed: int
    out_dir: str
    config: DatasetConfig
    data_dir: str | None = None
    render_threads: int | None = None
    source: Any = None

    @property
    def sample_id(self) -> str:
        """Folder name of the sample, ``str(self.id)``, e.g. ``"obj-vase__v0__two-colour-a"``."""
        return str(self.id)

    @property
    def scene(self) -> str:
        """The scene's name, ``self.id.scene``."""
        return self.id.scene

    @property
    def scene_folder(self) -> Path | None:
        """The folder of the task's scene file (``None`` for library and generated scenes):
        the sample records its ``csv:`` spectra relative to it (``export_sample``)."""
        return Path(self.source.path).parent if isinstance(self.source, FileSource) else None

    @classmethod
    def planned(
        cls, sid: SampleId, config: DatasetConfig, out_dir: str, **options: Any
    ) -> SampleTask:
        """The task of sample *sid*, seeded ``seed_from_key(config.seed, str(sid))``; *options*
        are the remaining fields (``data_dir``, ``render_threads``, ``source``)."""
        return cls(
            id=sid,
            seed=seed_from_key(config.seed, str(sid)),
            out_dir=out_dir,
            config=config,
            **options,
        )


@dataclass(frozen=True)
class SampleOutcome:
    """The result of one sample.

    Attributes
    ----------
    sample_id
        Which sample.
    status
        ``"built"`` or ``"skipped"`` (already complete with the same config hash).
    path
        The sample folder.
    seconds
        Wall time of the whole task in s (scene, render, export).
    render_seconds
        Wall time spent inside ``render_scene`` in s (Mitsuba plus its array conversions).
    mitsuba_seconds
        Time inside Mitsuba's ``render`` calls in s, as reported by the renderer's
        ``meta["timings"]``; equal to *render_seconds* when the renderer reports none.
    peak_rss_mb
        Peak resident memory of the worker process so far, MiB (``ru_maxrss``).
    """

    sample_id: str
    status: Literal["built", "skipped"]
    path: str
    seconds: float = 0.0
    render_seconds: float = 0.0
    mitsuba_seconds: float = 0.0
    peak_rss_mb: float = 0.0


@dataclass(frozen=True)
class SampleFailure:
    """A sample whose task raised; *error* is ``"ExceptionType: message"``."""

    sample_id: str
    error: str


def mitsuba_seconds(meta: dict[str, Any], fallback: float) -> float:
    """Seconds spent in Mitsuba's ``render`` calls, summed over the renderer's reported passes
    (``meta["timings"][pass_group]["seconds"]``); *fallback* when none are reported."""
    timings = meta.get("timings") if isinstance(meta, dict) else None
    if not isinstance(timings, dict):
        return fallback
    seconds = [
        float(t["seconds"])
        for t in timings.values()
        if isinstance(t, dict) and isinstance(t.get("seconds"), int | float)
    ]
    return sum(seconds) if seconds else fallback


def run_record(built: Sequence[SampleOutcome], start: float, relight: int) -> BuildRun:
    """A build run's record so far (``build-time.json``): the wall time since *start*
    (``time.perf_counter()``), the *built* samples' summed task time and Mitsuba's part of it,
    and the sample folders written (each built sample with its *relight* relit variants)."""
    return BuildRun(
        finished=utc_now(),
        wall_seconds=time.perf_counter() - start,
        samples_built=len(built) * (1 + relight),
        sample_seconds=sum(o.seconds for o in built),
        mitsuba_seconds=sum(o.mitsuba_seconds for o in built),
        cpus=usable_cpus(),
    )
