"""``spectrinsic dataset``: build (or resume) a dataset from a preset."""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any

from spectrinsic.errors import DatasetError

__all__ = ["register", "run"]

DEFAULT_OUT = "data/dataset"


def register(subparsers: Any) -> None:
    from spectrinsic.presets import preset_names

    p = subparsers.add_parser(
        "dataset",
        help="render the dataset (68 samples) with ground truth; resumable",
        description=(
            "Render the dataset layout of the thesis (8 objects x 4 conditions + 3 complex "
            "scenes x 3 views x 4 conditions) with ground-truth layers, then write "
            "manifest.json, DATASET.md and the gallery. Complete samples with the same config "
            "hash are skipped, so an interrupted build resumes where it stopped."
        ),
    )
    p.add_argument("--out", metavar="DIR", default=DEFAULT_OUT, help=f"dataset folder ({DEFAULT_OUT})")
    p.add_argument(
        "--preset", default="default", choices=preset_names(), help="quality preset (default)"
    )
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
        "--only",
        metavar="PATTERN",
        default=None,
        help="build only sample ids matching these comma-separated globs ('obj-*,*__white')",
    )
    p.add_argument("--spp", type=int, default=None, metavar="N",
                   help="override samples per pixel (the total over all batches)")
    p.add_argument("--batches", type=int, default=None, metavar="N",
                   help="override the number of independent batches the samples are split into "
                        "(>= 2 measures the noise; spp must be divisible by it)")
    p.add_argument("--no-denoise", action="store_true",
                   help="keep shading from the raw Monte Carlo irradiance (no OIDN)")
    p.add_argument(
        "--resolution",
        default=None,
        metavar="WxH",
        help="override the image size in pixels, e.g. 256x256",
    )
    p.set_defaults(func=run)


def _overrides(args: argparse.Namespace) -> dict[str, int]:
    changes: dict[str, int] = {}
    if args.spp is not None:
        changes["spp"] = args.spp
    if args.batches is not None:
        changes["batches"] = args.batches
    if args.no_denoise:
        changes["denoise"] = False
    if args.resolution is not None:
        w, sep, h = args.resolution.lower().partition("x")
        if not (sep and w.isdigit() and h.isdigit()):
            raise DatasetError(f"--resolution {args.resolution!r}; expected WIDTHxHEIGHT, e.g. 256x256")
        changes["width"], changes["height"] = int(w), int(h)
    return changes


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from spectrinsic.dataset import SampleFailure, build_dataset
    from spectrinsic.executors import make_executor
    from spectrinsic.presets import get_preset

    config = get_preset(args.preset, seed=args.seed).with_options(**_overrides(args))
    cores = os.cpu_count() or 1
    # One process whose Dr.Jit pool uses every core beat one single-threaded process per core
    # on the 2-core reference machine (28 s vs 42 s for 4 default samples): each process
    # compiles its own kernels and holds its own scene.
    workers = 1 if args.workers is None else args.workers
    if workers < 1:
        raise DatasetError(f"--workers {workers}; expected a positive integer")
    threads = args.threads
    if args.scheduler:
        executor = make_executor("dask", scheduler=args.scheduler)
        threads = threads if threads is not None else 1
        where = f"Dask scheduler {args.scheduler}"
    elif workers == 1:
        executor = make_executor("serial")
        where = "this process"
    else:
        executor = make_executor("process", workers=workers)
        threads = threads if threads is not None else max(1, cores // workers)
        where = f"{workers} local worker processes"

    bar: Any = None
    failures: list[str] = []

    def on_plan(n_todo: int, n_skipped: int) -> None:
        nonlocal bar
        print(
            f"spectrinsic dataset: preset {config.preset!r}, {n_todo} sample(s) to build, "
            f"{n_skipped} already complete, on {where}",
            file=sys.stderr,
        )
        bar = tqdm(total=n_todo, unit="sample", disable=args.quiet or n_todo == 0, file=sys.stderr)

    def progress(record: Any) -> None:
        if isinstance(record, SampleFailure):
            failures.append(record.sample_id)
        if bar is not None:
            bar.set_postfix_str(f"{record.sample_id}" + (f", {len(failures)} failed" if failures else ""))
            bar.update(1)

    try:
        report = build_dataset(
            args.out,
            config,
            executor=executor,
            only=args.only,
            data_dir=args.data_dir,
            render_threads=threads,
            on_plan=on_plan,
            progress=progress,
        )
    except KeyboardInterrupt:
        if bar is not None:
            bar.close()
        done = bar.n if bar is not None else 0
        print(f"spectrinsic dataset: {done} sample(s) finished before the interrupt", file=sys.stderr)
        raise
    if bar is not None:
        bar.close()

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
    for f in report.failed:
        lines.append(f"FAILED {f.sample_id}: {f.error}")
    print("\n".join(lines))
    if report.failed:
        print(
            f"spectrinsic dataset: {len(report.failed)} sample(s) failed: "
            + ", ".join(f.sample_id for f in report.failed)
            + "; re-run to retry them",
            file=sys.stderr,
        )
        return 1
    return 0
