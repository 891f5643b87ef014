"""``spectrinsic dataset``: build (or resume) a dataset from a preset."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from tqdm import tqdm

from spectrinsic.errors import DatasetError, SceneError, SpectrinsicError
from spectrinsic.gt_export.integrity import check_build_folder
from spectrinsic.gt_export.manifest import SPLIT_FRACTIONS
from spectrinsic.pipeline.dataset import SampleFailure, build_dataset
from spectrinsic.pipeline.executors import check_scheduler, choose_executor
from spectrinsic.pipeline.presets import PRESETS, DatasetConfig, get_preset, preset_names
from spectrinsic.pipeline.source_plan import file_sample, files_source, generator_source
from spectrinsic.render.budget import check_render_size
from spectrinsic.render.settings import INTEGRATORS
from spectrinsic.scenes.generators import GlossDistribution
from spectrinsic.scenes.sources import FileSource
from spectrinsic.scenes.yaml_limits import load_yaml_file
from spectrinsic.spectra import get_spectrum

__all__ = [
    "register",
    "run",
    "config_from_args",
    "preflight",
    "build",
    "material_map",
    "source_notes",
    "parse_resolution",
]

DEFAULT_OUT = "data/dataset"
#: Largest root seed and samples per pixel (Mitsuba's sampler takes unsigned 32-bit values).
UINT32_MAX = 2**32 - 1


def _presets_help() -> str:
    """The presets with their numbers, for ``--help``."""
    parts = [
        f"{name}: {c.width}x{c.height}, {c.render.batches} batch(es) x {c.render.batch_spp} spp, "
        f"depth {c.render.max_depth}, modes {'+'.join(c.render.modes)}"
        f"{', denoised' if c.denoise else ''}"
        for name, c in PRESETS.items()
    ]
    return "quality preset (default: default). " + "; ".join(parts)


def register(subparsers: Any) -> None:
    """Add the ``dataset`` subcommand to the CLI's *subparsers*."""
    p = subparsers.add_parser(
        "dataset",
        help="render the dataset (68 samples) with ground truth; resumable",
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
    _add_source_options(p.add_argument_group("scene source (default: the built-in library layout)"))
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
        "--only",
        metavar="PATTERN",
        default=None,
        help="build only sample ids matching these comma-separated globs ('obj-*,*__white')",
    )


def _add_quality_options(p: Any) -> None:
    """Overrides of the preset's sampling, denoising and image size."""
    p.add_argument(
        "--spp",
        type=int,
        default=None,
        metavar="N",
        help="override samples per pixel (the total over all batches)",
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
    p.add_argument(
        "--direct",
        action="store_true",
        help="also render direct light only, to record the energy ratio r per sample",
    )
    p.add_argument(
        "--store-transport",
        action="store_true",
        help="store each light's 31-band transport in every sample (transport.exr), so "
        "`spectrinsic relight` can relight it exactly; renders the diagonal modes "
        "light by light",
    )
    p.add_argument(
        "--relight",
        type=int,
        default=None,
        metavar="N",
        help="with --store-transport: also write N relit variants of every sample "
        "(<id>-relitK, random light spectra, seeded)",
    )
    p.add_argument(
        "--integrator",
        choices=INTEGRATORS,
        default=None,
        help="diagonal modes from one traversal (single, the default) or the passes; "
        "same pixels to float rounding, so not part of the config hash",
    )
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


def _add_source_options(src: Any) -> None:
    """Where the scenes come from: the library (default), a generator, or scene files."""
    src.add_argument(
        "--generator",
        metavar="NAME",
        default=None,
        help="generate scenes procedurally: objects-on-ground or rooms",
    )
    src.add_argument("--count", type=int, default=20, metavar="N", help="generated scenes (20)")
    src.add_argument(
        "--views", type=int, default=1, metavar="V", help="cameras per generated scene (1)"
    )
    src.add_argument(
        "--value-range",
        default="2,9",
        metavar="LO,HI",
        help="Munsell value range of generated materials (2,9)",
    )
    src.add_argument(
        "--chroma-range",
        default="0,16",
        metavar="LO,HI",
        help="Munsell chroma range of generated materials (0,16)",
    )
    src.add_argument(
        "--light-saturation",
        default=None,
        metavar="LO,HI",
        help="keep only coloured lights whose |Duv| (Ohno 2013: CIE 1960 uv distance "
        "from the Planckian locus) is in LO,HI; 0.02 is visibly tinted, at most "
        "0.15 for LO (default: any, 60%% from saturated LEDs and filtered lamps)",
    )
    src.add_argument(
        "--sfu",
        action="store_true",
        help="also draw SFU reflectances and illuminants (needs --data-dir)",
    )
    src.add_argument(
        "--glossy",
        type=float,
        default=0.0,
        metavar="F",
        help="fraction of generated materials made coated/glossy (plastic) (0)",
    )
    src.add_argument(
        "--metallic",
        type=float,
        default=0.0,
        metavar="F",
        help="fraction of generated materials made metal (Ag, Al, Au, Cu, Cr) (0)",
    )
    src.add_argument(
        "--roughness-range",
        default="0,0.3",
        metavar="LO,HI",
        help="GGX roughness range of glossy and metal materials (0,0.3)",
    )
    src.add_argument(
        "--scenes",
        nargs="+",
        metavar="PATH",
        default=None,
        help="render your own scene files (.yaml, .blend, .obj/.ply/.glb) with full ground truth",
    )
    src.add_argument(
        "--material-map",
        metavar="FILE",
        default=None,
        help="YAML/JSON mapping material name -> spectrum for .blend and mesh scenes",
    )
    src.add_argument(
        "--default-spectrum",
        metavar="NAME",
        default=None,
        help="reflectance of unmapped materials in .blend and mesh scenes",
    )
    src.add_argument(
        "--new-sample",
        action="store_true",
        help="render scenes a generated build saved (<dataset>/scenes/*.yaml) as new "
        "samples (id from the file name, seed from --seed) instead of "
        "reproducing their own sample (same id, same seed)",
    )


def _range(option: str, text: str) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in text.split(","))
    except ValueError:
        raise DatasetError(f"{option} {text!r}; expected LO,HI, e.g. 2,9") from None
    if lo > hi:
        raise DatasetError(f"{option} {text!r}; expected LO <= HI")
    return lo, hi


def material_map(path: str | None) -> dict[str, str]:
    """The ``--material-map`` file as ``{material name: spectrum name}`` (``{}`` for none)."""
    if path is None:
        return {}

    data = load_yaml_file(Path(path))
    if not isinstance(data, dict) or not all(
        isinstance(k, str) and isinstance(v, str) for k, v in data.items()
    ):
        raise DatasetError(
            f"--material-map {path!r}: expected a mapping of material name -> spectrum name"
        )
    return data


def _source(args: argparse.Namespace) -> str | None:
    """The config's ``source`` for --generator / --scenes (``None``: the library)."""
    if args.generator and args.scenes:
        raise DatasetError("--generator and --scenes exclude each other; give one")
    if args.generator:
        try:
            gloss = GlossDistribution(
                args.glossy, args.metallic, _range("--roughness-range", args.roughness_range)
            )
        except SceneError as exc:
            raise DatasetError(f"--glossy/--metallic/--roughness-range: {exc}") from None
        return generator_source(
            args.generator,
            args.count,
            views=args.views,
            sfu=args.sfu,
            value_range=_range("--value-range", args.value_range),
            chroma_range=_range("--chroma-range", args.chroma_range),
            gloss=gloss,
            light_saturation=None
            if args.light_saturation is None
            else _range("--light-saturation", args.light_saturation),
        )
    if args.scenes:
        size = None if args.resolution is None else parse_resolution(args.resolution)
        return files_source(
            args.scenes,
            materials=material_map(args.material_map),
            default_spectrum=args.default_spectrum,
            resolution=size,
            new_sample=getattr(args, "new_sample", False),
        )
    return None


def source_notes(config: DatasetConfig) -> list[str]:
    """What applies to each scene file of *config* (``--scenes``, ``render --ground-truth``):
    its size (the file's camera or --resolution) and its sample (a saved one, reproduced, or a
    new one); empty for the library and generators."""
    spec = json.loads(config.source or "{}")
    notes = []
    for entry in spec.get("scenes", ()):
        size = spec.get("resolution")
        where = (
            f"{size[0]}x{size[1]} (--resolution)"
            if size
            else "the file's camera size (--resolution to change it)"
        )
        sid, seed = file_sample(entry["path"], new_sample=bool(spec.get("new_sample")))
        sample = (
            f"reproduces its saved sample {sid} with seed {seed} (--new-sample for a new one)"
            if seed is not None
            else f"sample {sid}"
        )
        notes.append(f"{Path(entry['path']).name}: {where}; {sample}")
    return notes


#: Options copied into the config as they are when given (option dest -> config key).
_VALUE_OPTIONS: tuple[tuple[str, str], ...] = (
    ("spp", "spp"),
    ("batches", "batches"),
    ("relight", "relight"),
    ("noise_target", "noise_target"),
    ("max_batches", "max_batches"),
    ("integrator", "integrator"),
)
#: Switches and the config value each sets when given (option dest -> (config key, value)).
_SWITCHES: tuple[tuple[str, str, bool], ...] = (
    ("no_denoise", "denoise", False),
    ("direct", "direct", True),
    ("store_transport", "store_transport", True),
)


def _overrides(args: argparse.Namespace) -> dict[str, Any]:
    """The config changes the options ask for (getattr: ``render --ground-truth`` builds its
    own namespace of dataset options, without some of them)."""
    changes: dict[str, Any] = {}
    source = _source(args)
    if source is not None:
        changes["source"] = source
    for dest, key in _VALUE_OPTIONS:
        if getattr(args, dest, None) is not None:
            changes[key] = getattr(args, dest)
    for dest, key, value in _SWITCHES:
        if getattr(args, dest, False):
            changes[key] = value
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


def parse_resolution(text: str) -> tuple[int, int]:
    """``WIDTHxHEIGHT`` as two positive integers."""
    w, sep, h = text.lower().partition("x")
    if not (sep and w.isdigit() and h.isdigit() and int(w) > 0 and int(h) > 0):
        raise DatasetError(
            f"--resolution {text!r}; expected WIDTHxHEIGHT of positive integers, e.g. 256x256"
        )
    return int(w), int(h)


def preflight(
    out: str | Path,
    config: DatasetConfig,
    *,
    workers: int | None = None,
    threads: int | None = None,
    scheduler: str | None = None,
    rebuild: bool = False,
    data_dir: str | None = None,
) -> None:
    """Every refusal that needs no rendering, before anything is written or started."""
    if workers is not None and workers < 1:
        raise DatasetError(f"--workers {workers}; expected a positive integer")
    if threads is not None and threads < 1:
        raise DatasetError(f"--threads {threads}; expected a positive integer")
    if not 0 <= config.seed <= UINT32_MAX or config.render.spp > UINT32_MAX:
        raise DatasetError(
            f"--seed {config.seed} / --spp {config.render.spp}; expected a seed from 0 "
            f"to {UINT32_MAX} and at most {UINT32_MAX} samples per pixel"
        )
    check_build_folder(Path(out), config.config_hash(), rebuild=rebuild)
    _check_scene_files(config, data_dir)
    if scheduler:
        check_scheduler(scheduler)
    # two lights: the library's two-colour conditions, rendered once per light
    check_render_size(
        config.width,
        config.height,
        config.render,
        what=f"--resolution {config.width}x{config.height}",
        processes=workers or 1,
        n_lights=2,
    )


def _check_scene_files(config: Any, data_dir: str | None) -> None:
    """``--scenes``: every file reads as a valid scene with this material map and default
    spectrum, before the folder is stamped with the config (a bad file is an input error, not
    a failed sample)."""

    spec = json.loads(config.source or "{}")
    if "scenes" not in spec:
        return
    materials = spec.get("materials") or {}
    named = [("--default-spectrum", spec.get("default_spectrum"))]
    named += [(f"--material-map entry {k!r}", v) for k, v in sorted(materials.items())]
    for option, name in named:
        try:
            if name is not None:
                get_spectrum(name, data_dir=data_dir)
        except SpectrinsicError as exc:
            raise DatasetError(f"{option} {name!r}: {exc}") from exc
    width, height = spec.get("resolution") or (None, None)
    for entry in spec["scenes"]:
        FileSource(
            entry["path"],
            width,
            height,
            tuple(sorted(materials.items())),
            spec.get("default_spectrum"),
        ).build(data_dir)


def run(args: argparse.Namespace) -> int:
    config = config_from_args(args)
    preflight(
        args.out,
        config,
        workers=args.workers,
        threads=args.threads,
        scheduler=args.scheduler,
        rebuild=args.rebuild,
        data_dir=args.data_dir,
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
