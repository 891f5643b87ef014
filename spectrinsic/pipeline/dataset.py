"""Build a dataset: plan the samples, skip the complete ones, render and export the rest.

The pipeline per sample (:func:`build_sample`) is scene → render → ground truth:
:func:`spectrinsic.scenes.library.build`, :func:`spectrinsic.render.render_scene`,
:func:`spectrinsic.gt_export.export_sample`. ``export_sample`` writes into a temporary folder
and renames it into place, so a sample folder either is complete (its ``meta.json`` holds the
config hash) or does not exist under its final name: an interrupted build never leaves a sample
that looks complete, and re-running resumes where it stopped.

After all samples, :func:`finalize_dataset` writes ``manifest.json``, ``DATASET.md`` and the
gallery. Each sample's seed is ``seed_from_key(config.seed, sample_id)``, independent of the
order and the executor, so the same config and seed give the same pixels.
"""

from __future__ import annotations

import glob
import logging
import os
import resource
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

from ..errors import DiskFullError
from ..gt_export import (
    build_gallery,
    export_sample,
    sample_dirs,
    write_dataset_card,
    write_manifest,
)
from ..gt_export.dataset.build_time import BuildRun, record_build_run
from ..gt_export.folders.build_folder import (
    check_build_folder,
    remove_owned_temporaries,
    unmarked_on_error,
    write_marker,
)
from ..gt_export.folders.outfolder import folder_lock
from ..gt_export.relight.augment import RELIT_TAG, relit_problem, write_relit_variants
from ..gt_export.sample.integrity import remove_sample, replaceable_sample, sample_problem
from ..render import render_batches, set_thread_count
from ..render.base.variants import import_mitsuba
from ..render.probe import probe_luminance
from ..render.transport_render import render_transport_batches
from ..scenes.library import build
from ..scenes.sources import GeneratedSource
from ..spectra.camera_model import camera_model, camera_sensors
from .disk_space import check_disk_space
from .executors import Executor, SerialExecutor
from .presets import DatasetConfig
from .sample_plan import plan_samples
from .source_plan import save_generated
from .tasks import SampleFailure, SampleOutcome, SampleTask, mitsuba_seconds, run_record

__all__ = [
    "SampleTask",
    "SampleOutcome",
    "SampleFailure",
    "DatasetReport",
    "build_sample",
    "build_dataset",
    "finalize_dataset",
]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class DatasetReport:
    """What a build did.

    Attributes
    ----------
    out_dir
        The dataset folder.
    config
        The settings used.
    built, skipped, failed
        Per-sample outcomes.
    seconds
        Wall time of the whole build (including finalisation), s.
    finalized
        Whether manifest, dataset card and gallery were written.
    """

    out_dir: Path
    config: DatasetConfig
    built: tuple[SampleOutcome, ...] = ()
    skipped: tuple[SampleOutcome, ...] = ()
    failed: tuple[SampleFailure, ...] = ()
    seconds: float = 0.0
    finalized: bool = False
    files: dict[str, str] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        """True when no sample failed."""
        return not self.failed

    def timing_summary(self) -> dict[str, float]:
        """Mean s per built sample and the fraction of task time spent outside Mitsuba."""
        if not self.built:
            return {}
        total = sum(o.seconds for o in self.built)
        mitsuba = sum(o.mitsuba_seconds for o in self.built)
        return {
            "seconds_per_sample": total / len(self.built),
            "render_seconds_per_sample": sum(o.render_seconds for o in self.built)
            / len(self.built),
            "fraction_outside_mitsuba": (total - mitsuba) / total if total > 0 else 0.0,
            "peak_rss_mb": max(o.peak_rss_mb for o in self.built),
        }


def build_sample(task: SampleTask) -> SampleOutcome:
    """Build one sample: scene → render → ground-truth export. Runs in a worker.

    Returns
    -------
    SampleOutcome
        Status ``"built"`` with timings and the worker's peak memory.
    """
    set_thread_count(task.render_threads)  # one pool per worker, sized to its share of cores
    cfg = task.config
    t0 = time.perf_counter()
    scene = _task_scene(task)
    t_render = time.perf_counter()
    transport = None
    if cfg.store_transport:  # the per-light transport kept (split by light) for relighting
        transport, result = render_transport_batches(
            scene, cfg.render, seed=task.seed, data_dir=task.data_dir
        )
    else:
        result = render_batches(scene, cfg.render, seed=task.seed, data_dir=task.data_dir)
    render_seconds = time.perf_counter() - t_render
    if cfg.render.direct:  # the energy ratio r of Eq. 5.8, for the card's diversity plots
        mode = "spectral" if "spectral" in result.direct else next(iter(result.direct))
        scene.metadata["energy_ratio_r"] = float(result.energy_ratio(mode))
    path = export_sample(
        task.out_dir,
        scene,
        result,
        cfg.layer_settings(task.data_dir).for_scene_folder(task.scene_folder),
        sample_id=task.sample_id,
        config=cfg.to_dict(),
        seed=task.seed,
        transport=transport,
    )
    if cfg.relight:
        write_relit_variants(
            path, cfg.relight, seed=task.seed, data_dir=task.data_dir, scene_dir=task.scene_folder
        )
    seconds = time.perf_counter() - t0
    return SampleOutcome(
        sample_id=task.sample_id,
        status="built",
        path=str(path),
        seconds=seconds,
        render_seconds=render_seconds,
        mitsuba_seconds=mitsuba_seconds(result.meta, render_seconds),
        peak_rss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    )


def _task_scene(task: SampleTask) -> Any:
    """The task's scene: from its source (a generated one is saved as a scene file; its views
    are judged on a probe render, issue 47), else the library."""
    if task.source is None:
        cfg = task.config
        return build(
            task.id.scene,
            view=task.id.view,
            condition=task.id.condition,
            seed=cfg.seed,
            width=cfg.width,
            height=cfg.height,
        )

    import_mitsuba()  # set up before a Mitsuba XML read imports it (the libLLVM Dr.Jit loads)
    if not isinstance(task.source, GeneratedSource):
        return task.source.build(task.data_dir)
    probe = partial(probe_luminance, data_dir=task.data_dir, variant=task.config.render.variant)
    scene = task.source.build(task.data_dir, probe=probe)
    save_generated(task.out_dir, task.sample_id, scene, task.seed)
    return scene


def build_dataset(
    out_dir: str | os.PathLike[str],
    config: DatasetConfig,
    *,
    executor: Executor | None = None,
    only: Sequence[str] | str | None = None,
    data_dir: str | os.PathLike[str] | None = None,
    render_threads: int | None = None,
    task_fn: Callable[[SampleTask], SampleOutcome] = build_sample,
    on_plan: Callable[[int, int], None] | None = None,
    progress: Callable[[SampleOutcome | SampleFailure], None] | None = None,
    finalize: bool = True,
    rebuild: bool = False,
    disk_check: bool = True,
) -> DatasetReport:
    """Build (or resume) the dataset in *out_dir*.

    Parameters
    ----------
    out_dir
        Dataset folder (created if needed). It must be new, empty, or a spectrinsic dataset.
    config
        Build settings; samples whose folder is complete and intact for
        ``config.config_hash()`` are skipped, the others (re-)rendered.
    executor
        Where tasks run (default: serially in this process).
    only
        Glob pattern(s) selecting sample ids (see :func:`plan_samples`).
    task_fn
        The per-sample function (default :func:`build_sample`); picklable for process and
        Dask executors.
    on_plan
        Called once with ``(n_to_build, n_skipped)`` before building starts.
    progress
        Called with each sample's outcome or failure as it finishes.
    finalize
        Write manifest, dataset card and gallery at the end (only if a sample is complete).
    rebuild
        Allow a folder built with another config: its samples are removed and rebuilt with
        *config* (together with those *only* selects), so the folder holds one config.
    disk_check
        Refuse a build whose samples to build cannot fit in the free space of *out_dir*
        (:func:`spectrinsic.pipeline.disk_space.check_disk_space`); False goes ahead anyway.

    Returns
    -------
    DatasetReport
        Built, skipped and failed samples and the timings. A failed sample does not stop the
        others. ``KeyboardInterrupt`` propagates after completed samples are safely in place.

    Raises
    ------
    DatasetError
        Before anything is written, if *out_dir* is not a folder this build may write into
        (see :func:`spectrinsic.gt_export.folders.build_folder.check_build_folder`) or a sample's folder
        holds files spectrinsic did not write.
    FolderLockedError
        Another build holds *out_dir* (its advisory lock); the message names its pid, host and
        start time.
    DiskFullError
        When the disk is full: the build stops at the first sample that hits it; with
        *disk_check*, before the first sample if the estimate does not fit.
    """

    out = Path(out_dir)
    if config.camera:  # three sound curves (a data-directory camera needs --data-dir): one line
        camera_sensors(camera_model(config.camera), data_dir=data_dir)
    new = check_build_folder(out, config.config_hash(), rebuild=rebuild) is None  # before mkdir
    with folder_lock(out), unmarked_on_error(out, new):  # one build per folder, held
        return _build_locked(
            out,
            config,
            executor=executor,
            only=only,
            data_dir=data_dir,
            render_threads=render_threads,
            task_fn=task_fn,
            on_plan=on_plan,
            progress=progress,
            finalize=finalize,
            rebuild=rebuild,
            disk_check=disk_check,
        )


def _build_locked(
    out: Path,
    config: DatasetConfig,
    *,
    executor: Executor | None,
    only: Sequence[str] | str | None,
    data_dir: str | os.PathLike[str] | None,
    render_threads: int | None,
    task_fn: Callable[[SampleTask], SampleOutcome],
    on_plan: Callable[[int, int], None] | None,
    progress: Callable[[SampleOutcome | SampleFailure], None] | None,
    finalize: bool,
    rebuild: bool,
    disk_check: bool,
) -> DatasetReport:
    """:func:`build_dataset` once the folder's lock is held."""
    start = time.perf_counter()
    executor = executor if executor is not None else SerialExecutor()
    kw: dict[str, Any] = {"data_dir": data_dir, "render_threads": render_threads}
    todo, skipped = _prepare(out, config, only=only, rebuild=rebuild, disk_check=disk_check, **kw)
    # Rooms cost ~5x objects and the layout lists all objects first; a fixed pseudo-random
    # order (by sample seed) mixes them, so the progress bar's ETA holds from the start.
    todo.sort(key=lambda t: (t.seed, t.sample_id))
    log.info("%d sample(s) to build, %d already complete", len(todo), len(skipped))
    if on_plan is not None:
        on_plan(len(todo), len(skipped))
    built, failed = _run(executor, task_fn, todo, progress)
    files: dict[str, str] = {}
    if finalize:
        files = finalize_dataset(
            out, config, data_dir=data_dir, run=run_record(built, start, config.relight)
        )
    return DatasetReport(
        out_dir=out,
        config=config,
        built=tuple(sorted(built, key=lambda o: o.sample_id)),
        skipped=tuple(skipped),
        failed=tuple(sorted(failed, key=lambda f: f.sample_id)),
        seconds=time.perf_counter() - start,
        finalized=bool(files),
        files=files,
    )


def _prepare(
    out: Path,
    config: DatasetConfig,
    *,
    only: Sequence[str] | str | None,
    data_dir: str | os.PathLike[str] | None,
    render_threads: int | None,
    rebuild: bool,
    disk_check: bool,
) -> tuple[list[SampleTask], list[SampleOutcome]]:
    """Check *out*, split the planned samples into to-build and intact, then mark the folder.

    Everything that can refuse the build runs before the first write.
    """
    config_hash = config.config_hash()
    previous = check_build_folder(out, config_hash, rebuild=rebuild)
    kw: dict[str, Any] = {"data_dir": data_dir, "render_threads": render_threads}
    tasks = plan_samples(out, config, only=only, **kw)
    if previous is not None and previous != config_hash:
        # --rebuild: every sample of the old config present on disk is rebuilt too
        chosen = {t.sample_id for t in tasks}
        tasks += [
            t
            for t in plan_samples(out, config, **kw)
            if t.sample_id not in chosen and (out / t.sample_id).exists()
        ]
    todo, skipped, stale = [], [], []
    for t in tasks:
        folder = out / t.sample_id
        problem = sample_problem(folder, config_hash)
        if problem is None and config.relight:  # a source whose relit variants are not all there
            problem = relit_problem(folder, config.relight, config_hash)
        if problem is None:
            skipped.append(SampleOutcome(t.sample_id, "skipped", str(folder)))
            continue
        replaceable_sample(folder)  # refuses a folder (or a file in it) spectrinsic did not write
        if problem != "absent":
            log.warning("sample %s: %s; re-rendering it", t.sample_id, problem)
            stale.append(folder)
            stale += _relit_variants(folder)  # made from the old render: go with it
        todo.append(t)
    if disk_check:  # the last refusal: nothing is written before it
        check_disk_space(out, config, len(todo))
    write_marker(out, config_hash)
    for path in remove_owned_temporaries(out):
        log.info("removed %s, left by an interrupted build", path.name)
    if previous is not None and previous != config_hash:
        log.warning(
            "--rebuild: removing %d sample(s) built with config %s", len(stale), previous[:12]
        )
        for folder in stale:
            remove_sample(folder)  # no old-config sample survives a failed re-render
    return todo, skipped


def _relit_variants(folder: Path) -> list[Path]:
    """The relit variants (``dataset --relight``) on disk beside the sample in *folder*."""
    found = sorted(
        p for p in folder.parent.glob(glob.escape(folder.name + RELIT_TAG) + "*") if p.is_dir()
    )
    for path in found:
        replaceable_sample(path)  # refuses a folder (or a file in it) spectrinsic did not write
    return found


def _run(
    executor: Executor,
    task_fn: Callable[[SampleTask], SampleOutcome],
    todo: list[SampleTask],
    progress: Callable[[SampleOutcome | SampleFailure], None] | None,
) -> tuple[list[SampleOutcome], list[SampleFailure]]:
    """Run the tasks; a failed sample does not stop the others, a full disk stops them all."""
    built: list[SampleOutcome] = []
    failed: list[SampleFailure] = []
    for task, outcome in executor.map_unordered(task_fn, todo):
        if isinstance(outcome, DiskFullError):
            raise outcome  # every further sample would fail the same way
        record: SampleOutcome | SampleFailure
        if isinstance(outcome, BaseException):
            record = SampleFailure(task.sample_id, f"{type(outcome).__name__}: {outcome}")
            log.error("sample %s failed: %s", task.sample_id, record.error)
            failed.append(record)
        else:
            record = outcome
            built.append(outcome)
        if progress is not None:
            progress(record)
    return built, failed


def finalize_dataset(
    out_dir: str | os.PathLike[str],
    config: DatasetConfig,
    *,
    data_dir: str | os.PathLike[str] | None = None,
    run: BuildRun | None = None,
) -> dict[str, str]:
    """Write ``manifest.json``, ``DATASET.md`` and the gallery; return their paths by kind.

    First removes spectrinsic's temporaries, whichever worker left them (all have finished).
    A folder without any complete sample gets nothing (``{}``): no empty manifest. *run* (this
    run's times so far) goes into ``build-time.json``, which the card states.
    """
    start = time.perf_counter()
    out = Path(out_dir)
    for path in remove_owned_temporaries(out):
        log.info("removed %s, left by a worker that died", path.name)
    if not sample_dirs(out):
        return {}
    cfg = config.to_dict()
    manifest = write_manifest(out, cfg, data_dir=data_dir, split_fractions=config.split_fractions)
    if run is not None:  # the manifest's hashing is part of this run's wall time
        record_build_run(out, config.config_hash(), run.finished_after(time.perf_counter() - start))
    card = write_dataset_card(out, cfg)
    gallery = build_gallery(out)
    return {"manifest": str(manifest), "card": str(card), "gallery": str(gallery)}
