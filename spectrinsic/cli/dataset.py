"""``spectrinsic dataset``: build (or resume) a dataset from a preset."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from tqdm import tqdm

from ..errors import DatasetError
from ..gt_export.dataset.manifest import SPLIT_FRACTIONS
from ..gt_export.folders.build_folder import check_build_folder
from ..pipeline.dataset import SampleFailure, build_dataset
from ..pipeline.executors import check_scheduler, choose_executor
from ..pipeline.presets import PRESETS, DatasetConfig, get_preset, preset_names
from ..pipeline.source_plan import check_integrator_plan
from ..render.budget import PLANNED_LOAD, RenderLoad, check_render_size
from ..render.settings import INTEGRATORS, UINT32_MAX
from .dataset_layers import add_extra_layer_options, layer_changes
from .dataset_scene_files import check_scene_files, source_notes
from .dataset_source import add_source_options, parse_resolution, source_from_args
from .dataset_variant import add_variant_option, check_variant

__all__ = [
    "register",
    "run",
    "config_from_args",
    "preflight",
    "build",
]

DEFAULT_OUT = "data/dataset"


def _presets_help() -> str:
    """The presets with their numbers, for ``--help``."""
    parts = [
        f"{name}: {c.width}x{c.height}, {c.render.batches} batch(es) x {c.render.batch_spp} spp"
        f" (spectral {c.render.spectral_batch_spp}), "
        f"depth {c.render.max_depth}, modes {'+'.join(c.render.modes)}"
        f"{', denoised' if c.denoise else ''}"
        for name, c in PRESETS.items()
    ]
    return "quality preset (default: default). " + "; ".join(parts)


def register(subparsers: Any) -> None:
    """Add the ``dataset`` subcommand to the CLI's *subparsers*."""
    p = subparsers.add_parser(
        "dataset",
        help="render a dataset with ground truth: the thesis' 68 library samples, generated "
        "scenes (--generator) or your own scene files (--scenes); resumable",
        description=(
            "Render the dataset layout of the thesis (8 objects x 4 conditions + 3 complex "
            "scenes x 3 views x 4 conditions) with ground-truth layers, then write "
            "manifest.json, DATASET.md and the gallery. Complete samples with the same config "
            "hash whose files match their SHA-256 are skipped, so an interrupted build resumes "
            "where it stopped. --out must be new, empty, or a dataset built with the same "
            "config (--rebuild to rebuild one built with another)."
        ),
    )
    _add_build_options(p)
    _add_quality_options(p)
    add_source_options(p.add_argument_group("scene source (default: the built-in library layout)"))
    p.add_argument(
        "--split-fractions",
        default=None,
        metavar="TRAIN,VAL,TEST",
        help="shares of the scenes in the train, val and test splits (0.8,0.1,0.1); from 3 "
        "scenes on every split holds a scene; not hashed (a resume rewrites the manifest)",
    )
    p.add_argument(
        "--rebuild",
        action="store_true",
        help="--out was built with another config: rebuild its samples with this one",
    )
    p.set_defaults(func=run)


def _add_build_options(p: Any) -> None:
    """Where the dataset goes, which preset and seed, and what it runs on."""
    p.add_argument(
        "--out", metavar="DIR", default=DEFAULT_OUT, help=f"dataset folder ({DEFAULT_OUT})"
    )
    p.add_argument("--preset", default="default", choices=preset_names(), help=_presets_help())
    p.add_argument("--seed", type=int, default=0, help="root seed (0)")
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help=(
            "local worker processes (default 1: build in this process, rendering on every "
            "core; more pay off on machines with many cores)"
        ),
    )
    p.add_argument(
        "--threads",
        type=int,
        default=None,
        metavar="N",
        help="render threads per worker (default: cores / workers)",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        default=None,
        help="run on a Dask distributed cluster (tcp://host:8786) instead of local workers",
    )
    p.add_argument(
        "--ignore-disk-space",
        action="store_true",
        help="build even if the disk space the plan needs (estimated from the preset, "
        "resolution, layers and sample count) is more than is free where --out lies",
    )
    p.add_argument(
        "--only",
        metavar="PATTERN",
        default=None,
        help="build only sample ids matching these comma-separated globs ('obj-*,*__white')",
    )


def _add_quality_options(p: Any) -> None:
    """Overrides of the preset's sampling, denoising and image size."""
    _add_sampling_options(p)
    add_extra_layer_options(p)
    _add_rendering_options(p)


def _add_sampling_options(p: Any) -> None:
    """Samples per pixel, batches and adaptive sampling."""
    p.add_argument(
        "--spp",
        type=int,
        default=None,
        metavar="N",
        help="override samples per pixel (the total over all batches)",
    )
    p.add_argument(
        "--spectral-spp",
        type=int,
        default=None,
        metavar="N",
        help="override samples per pixel of the spectral Monte Carlo pass (total over all "
        "batches; the reference image and ground truth come from the diagonal modes' --spp)",
    )
    p.add_argument(
        "--batches",
        type=int,
        default=None,
        metavar="N",
        help="override the number of independent batches the samples are split into "
        "(>= 2 measures the noise; spp must be divisible by it)",
    )
    p.add_argument(
        "--noise-target",
        type=float,
        default=None,
        metavar="F",
        help="adaptive sampling: add batches until the image's median relative "
        "standard error is below F (e.g. 0.02) or --max-batches is reached",
    )
    p.add_argument(
        "--max-batches",
        type=int,
        default=None,
        metavar="N",
        help="cap of the adaptive batches (default 4 x batches)",
    )


def _add_rendering_options(p: Any) -> None:
    """How the modes are rendered, denoised, and at what image size."""
    p.add_argument(
        "--integrator",
        choices=INTEGRATORS,
        default=None,
        help="diagonal modes from one traversal (single, the default) or the passes; "
        "same pixels to float rounding, so not part of the config hash",
    )
    add_variant_option(p)
    p.add_argument(
        "--no-denoise",
        action="store_true",
        help="keep shading from the raw Monte Carlo irradiance (no OIDN)",
    )
    p.add_argument(
        "--resolution",
        default=None,
        metavar="WxH",
        help="override the image size in pixels, e.g. 256x256",
    )


#: Options copied into the config as they are when given (option dest -> config key).
_VALUE_OPTIONS: tuple[tuple[str, str], ...] = (
    ("spp", "spp"),
    ("spectral_spp", "spectral_spp"),
    ("batches", "batches"),
    ("relight", "relight"),
    ("noise_target", "noise_target"),
    ("max_batches", "max_batches"),
    ("integrator", "integrator"),
    ("variant", "variant"),
)
#: Switches and the config value each sets when given (option dest -> (config key, value)).
_SWITCHES: tuple[tuple[str, str, bool], ...] = (
    ("no_denoise", "denoise", False),
    ("direct", "direct", True),
)


def _overrides(args: argparse.Namespace) -> dict[str, Any]:
    """The config changes the options ask for (getattr: ``render --ground-truth`` builds its
    own namespace of dataset options, without some of them)."""
    changes: dict[str, Any] = {}
    if (
        getattr(args, "max_batches", None) is not None
        and getattr(args, "noise_target", None) is None
    ):
        raise DatasetError("--max-batches applies to --noise-target (the adaptive batches' cap)")
    source = source_from_args(args)
    if source is not None:
        changes["source"] = source
    for dest, key in _VALUE_OPTIONS:
        if getattr(args, dest, None) is not None:
            changes[key] = getattr(args, dest)
    for dest, key, value in _SWITCHES:
        if getattr(args, dest, False):
            changes[key] = value
    changes.update(layer_changes(args))
    if args.resolution is not None:
        changes["width"], changes["height"] = parse_resolution(args.resolution)
    if getattr(args, "split_fractions", None) is not None:
        changes["split_fractions"] = _split_fractions(args.split_fractions)
    return changes


def _split_fractions(text: str) -> tuple[tuple[str, float], ...]:
    """``TRAIN,VAL,TEST`` shares (each > 0, summing to 1; checked by the config)."""
    try:
        shares = [float(v) for v in text.split(",")]
    except ValueError:
        shares = []
    if len(shares) != len(SPLIT_FRACTIONS):
        raise DatasetError(
            f"--split-fractions {text!r}; expected TRAIN,VAL,TEST shares, e.g. 0.8,0.1,0.1"
        )
    return tuple((name, v) for (name, _), v in zip(SPLIT_FRACTIONS, shares, strict=True))


def preflight(
    out: str | Path,
    config: DatasetConfig,
    *,
    workers: int | None = None,
    threads: int | None = None,
    scheduler: str | None = None,
    rebuild: bool = False,
    data_dir: str | None = None,
    quiet: bool = False,
) -> None:
    """Every refusal that needs no rendering, before anything is written or started (what a
    scene file's read fixed or approximated said on stderr unless *quiet*)."""
    if workers is not None and workers < 1:
        raise DatasetError(f"--workers {workers}; expected a positive integer")
    if threads is not None and threads < 1:
        raise DatasetError(f"--threads {threads}; expected a positive integer")
    spp = max(config.render.spp, config.render.spectral_spp or 0)
    if not 0 <= config.seed <= UINT32_MAX or spp > UINT32_MAX:
        raise DatasetError(
            f"--seed {config.seed} / --spp {spp}; expected a seed from 0 "
            f"to {UINT32_MAX} and at most {UINT32_MAX} samples per pixel"
        )
    check_build_folder(Path(out), config.config_hash(), rebuild=rebuild)
    scenes = check_scene_files(config, data_dir, quiet=quiet)
    check_integrator_plan(config)  # integrator x materials: every sample would fail
    if scheduler:
        check_scheduler(scheduler)
    sizes = [
        (f"scene {s.name!r} at", s.camera.width, s.camera.height, RenderLoad.of_scene(s))
        for s in scenes
    ] or [("--resolution", config.width, config.height, PLANNED_LOAD)]
    for what, width, height, load in sizes:
        check_render_size(
            width,
            height,
            config.render,
            what=f"{what} {width}x{height}",
            processes=workers or 1,
            load=load,
            data_dir=data_dir,
        )


def run(args: argparse.Namespace) -> int:
    check_variant(args)
    config = config_from_args(args)
    preflight(
        args.out,
        config,
        workers=args.workers,
        threads=args.threads,
        scheduler=args.scheduler,
        rebuild=args.rebuild,
        data_dir=args.data_dir,
        quiet=getattr(args, "quiet", False),
    )
    return build(
        args.out,
        config,
        only=args.only,
        workers=args.workers,
        threads=args.threads,
        scheduler=args.scheduler,
        rebuild=args.rebuild,
        data_dir=args.data_dir,
        quiet=args.quiet,
        disk_check=not args.ignore_disk_space,
    )


def config_from_args(args: argparse.Namespace) -> DatasetConfig:
    """The preset named by ``--preset`` with ``--seed`` and every override of the options."""
    return get_preset(args.preset, seed=args.seed).with_options(**_overrides(args))


def build(
    out: str | Path,
    config: DatasetConfig,
    *,
    only: str | None = None,
    workers: int | None = None,
    threads: int | None = None,
    scheduler: str | None = None,
    rebuild: bool = False,
    data_dir: str | None = None,
    quiet: bool = False,
    disk_check: bool = True,
) -> int:
    """Build *config* into *out* with a progress bar and print the summary; the exit status.

    The one path from a command line to :func:`~spectrinsic.pipeline.dataset.build_dataset`,
    shared by ``dataset`` and ``render --ground-truth``.
    """
    choice = choose_executor(workers=workers, threads=threads, scheduler=scheduler)
    if not quiet:
        for note in source_notes(config):
            print(f"spectrinsic dataset: {note}", file=sys.stderr)
    executor, render_threads, where = choice.executor, choice.render_threads, choice.where

    bar: Any = None
    failures: list[str] = []

    def on_plan(n_todo: int, n_skipped: int) -> None:
        nonlocal bar
        if not quiet:
            print(
                f"spectrinsic dataset: preset {config.preset!r}, {n_todo} sample(s) to build, "
                f"{n_skipped} already complete, on {where}",
                file=sys.stderr,
            )
        bar = tqdm(total=n_todo, unit="sample", disable=quiet or n_todo == 0, file=sys.stderr)

    def progress(record: Any) -> None:
        if isinstance(record, SampleFailure):
            failures.append(record.sample_id)
        if bar is not None:
            bar.set_postfix_str(
                f"{record.sample_id}" + (f", {len(failures)} failed" if failures else "")
            )
            bar.update(1)

    try:
        report = build_dataset(
            out,
            config,
            executor=executor,
            only=only,
            data_dir=data_dir,
            render_threads=render_threads,
            rebuild=rebuild,
            on_plan=on_plan,
            progress=progress,
            disk_check=disk_check,
        )
    except KeyboardInterrupt:
        done = bar.n if bar is not None else 0
        print(
            f"spectrinsic dataset: {done} sample(s) finished before the interrupt", file=sys.stderr
        )
        raise
    finally:
        if bar is not None:
            bar.close()
    print("\n".join(_summary(report)))
    if report.failed:
        print(
            f"spectrinsic dataset: {len(report.failed)} sample(s) failed: "
            + ", ".join(f.sample_id for f in report.failed)
            + "; re-run to retry them",
            file=sys.stderr,
        )
        return 1
    return 0


def _summary(report: Any) -> list[str]:
    """The lines printed after a build: counts, timings, files written, failed samples."""
    timing = report.timing_summary()
    lines = [
        f"built {len(report.built)}, skipped {len(report.skipped)}, failed {len(report.failed)} "
        f"in {report.seconds:.1f} s",
    ]
    if timing:
        lines.append(
            f"{timing['seconds_per_sample']:.2f} s per sample, "
            f"{100 * timing['fraction_outside_mitsuba']:.0f} % outside Mitsuba, "
            f"peak memory {timing['peak_rss_mb']:.0f} MiB per worker"
        )
    lines.append(f"dataset: {report.out_dir.resolve()}")
    for kind, path in report.files.items():
        lines.append(f"  {kind}: {path}")
    if not report.finalized:
        lines.append("  no complete sample: manifest, DATASET.md and gallery not written")
    for f in report.failed:
        lines.append(f"FAILED {f.sample_id}: {f.error}")
    return lines
