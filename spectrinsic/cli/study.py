"""``spectrinsic study``: the thesis' studies, printed and written as JSON, CSV and PNG.

* ``reconstruction-error``: Table 5.2 and its extension (:mod:`spectrinsic.studies.reconstruction`);
* ``photometric``: Table 4.4 (:mod:`spectrinsic.studies.photometric`);
* ``rendering``: the rendering study (:mod:`spectrinsic.studies.rendering`);
* ``sim2real``: the sim-to-real study (:mod:`spectrinsic.studies.sim2real`).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from tqdm import tqdm

from ..errors import StudyError
from ..gt_export.folders.staged_output import staged_output
from ..learn.torch_import import require_torch
from ..studies.photometric import CAMERA_BALANCES
from ..studies.photometric.compute import default_cameras
from ..studies.registry import STUDIES, StudyOptions, run_study
from ..studies.rendering import QUALITIES
from ..studies.sim2real import PRESETS as SIM2REAL_PRESETS

__all__ = ["register", "run"]

#: Root seed of the photometric study's random scenes unless ``--seed`` is given.
DEFAULT_SEED = 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "study",
        help="run a study of the thesis (Table 5.2, Table 4.4, rendering)",
        description="Run a study, print its table and write JSON, CSV and PNG files into --out. "
        + " ".join(f"{s.name}: {s.summary}." for s in STUDIES.values()),
    )
    p.add_argument("study", choices=tuple(STUDIES), help="which study")
    p.add_argument(
        "--out", type=Path, default=Path("results"), help="output folder (default: results)"
    )
    p.add_argument(
        "--seed",
        type=int,
        default=DEFAULT_SEED,
        help=f"root seed of random choices (default: {DEFAULT_SEED})",
    )
    p.add_argument(
        "--include-ie",
        action="store_true",
        help="photometric: add the Image Engineering 2024 cameras of the data directory",
    )
    p.add_argument(
        "--camera-balance",
        default=None,
        choices=CAMERA_BALANCES,
        help="photometric: normalisation of the camera curves (default: "
        "equal-energy-white, the one giving the thesis' SC3 behaviour)",
    )
    p.add_argument(
        "--no-extension",
        action="store_true",
        help="reconstruction-error: only Table 5.2, without the extended sweep",
    )
    p.add_argument(
        "--quality",
        default=None,
        choices=tuple(QUALITIES),
        help="rendering: quality preset (default: default, < 10 min on 2 cores)",
    )
    p.add_argument(
        "--preset",
        default=None,
        choices=tuple(SIM2REAL_PRESETS),
        help="sim2real: size preset (default: small, about an hour on 2 CPU cores; large for "
        "a GPU or a cluster)",
    )
    p.set_defaults(func=run)


@contextmanager
def _progress(quiet: bool, what: str) -> Iterator[Callable[..., None]]:
    """A progress callback (a tqdm bar on stderr, or nothing with -q)."""
    if quiet:
        yield lambda *a, **k: None
        return

    bar = tqdm(desc=what, unit="step", file=sys.stderr, leave=False)

    def step(message: Any = None, *_: Any, **__: Any) -> None:
        if message is not None:
            bar.set_postfix_str(str(message)[:60], refresh=False)
        bar.update(1)

    try:
        yield step
    finally:
        bar.close()


def _print_paths(paths: dict[str, Path]) -> None:
    for path in paths.values():
        print(f"wrote {path}")


def run(args: argparse.Namespace) -> int:
    _check_options(args)
    with staged_output(Path(args.out)) as stage:  # a failed run leaves --out as it was
        options = StudyOptions(
            seed=args.seed,
            include_ie=args.include_ie,
            camera_balance=args.camera_balance,
            extension=not args.no_extension,
            quality=args.quality,
            preset=args.preset,
        )
        with _progress(bool(getattr(args, "quiet", False)), args.study) as progress:
            done = run_study(
                args.study,
                stage,
                options,
                data_dir=getattr(args, "data_dir", None),
                progress=progress,
            )
    print(done.text)
    _print_paths({k: Path(args.out) / v.relative_to(stage) for k, v in done.paths.items()})
    return 0


#: Options of one study each (dest -> (study, default)): given to another, one is refused
#: in one line instead of ignored; not given, it takes its default.
STUDY_OPTIONS: dict[str, tuple[str, object]] = {
    "include_ie": ("photometric", False),
    "camera_balance": ("photometric", "equal-energy-white"),
    "no_extension": ("reconstruction-error", False),
    "quality": ("rendering", "default"),
}


def _check_options(args: argparse.Namespace) -> None:
    """Refusals that need no computation, before the output folder is made."""
    if args.preset is not None and args.study != "sim2real":
        raise StudyError(f"--preset {args.preset}: applies to sim2real only, not {args.study}")
    for dest, (study, default) in STUDY_OPTIONS.items():
        value = getattr(args, dest)
        if value not in (None, False) and args.study != study:
            raise StudyError(
                f"--{dest.replace('_', '-')} applies to the {study} study; this is {args.study}"
            )
        if value is None:
            setattr(args, dest, default)
    if args.study == "sim2real":
        require_torch("study sim2real")
    if args.study == "photometric" and args.include_ie:
        data_dir = getattr(args, "data_dir", None)
        if not any(n.endswith("[IE]") for n in default_cameras(data_dir=data_dir, include_ie=True)):
            where = (
                f"--data-dir {data_dir!r}"
                if data_dir
                else "no data directory (--data-dir, $SPECTRINSIC_DATA)"
            )
            raise StudyError(
                f"--include-ie: {where} holds no Image Engineering cameras; "
                "give the data directory that has them, or leave --include-ie out"
            )
