"""``spectrinsic evaluate``: score decomposers, or a user's predictions, on a rendered dataset."""

from __future__ import annotations

import argparse
import csv
import fnmatch
import logging
from pathlib import Path
from typing import Any, Literal

from tqdm import tqdm

from ..decompose.evaluation.evaluate import EvaluationResult, evaluate
from ..decompose.evaluation.mit import evaluate_mit, mit_folder_objects
from ..decompose.evaluation.predictions import Predictions
from ..decompose.evaluation.scored import add_scored_section, describe_scored
from ..decompose.evaluation.targets import TARGETS
from ..decompose.methods.registry import available_decomposers, get_decomposer
from ..decompose.report import write_report
from ..decompose.report.mit import MIT_FIGURE, write_mit_report
from ..errors import DatasetError
from ..gt_export.dataset.loader import load_sample
from ..gt_export.folders.outfolder import check_output_folder
from ..gt_export.folders.staged_output import staged_output
from ..gt_export.sample import sample_dirs
from ..path_kinds import folder_problem

__all__ = ["register", "run", "DEFAULT_DATASET", "DEFAULT_OUT"]

DEFAULT_DATASET = "data/dataset"
DEFAULT_OUT = "results/evaluation"

log = logging.getLogger(__name__)


def register(subparsers: Any) -> None:
    """Add the ``evaluate`` subcommand to the CLI's *subparsers*."""
    p = subparsers.add_parser(
        "evaluate",
        help="score decomposers or your own predictions on a rendered dataset "
        "(thesis Tables 5.1, 5.3, 5.4)",
        description=(
            "Decompose every sample of a dataset with each method, or read a method's outputs "
            "with --predictions, score reflectance and shading (LMSE, aLMSE, MSE, correlation, "
            "DSSIM, angular error, WHDR, shading chromaticity, MAW-style intensity/chromaticity "
            "split), and write scores.csv, tables like Tables 5.3/5.4 and 5.1 (markdown + CSV), "
            "REPORT.md, a figure per sample and every estimate as EXR. Predictions layout: "
            "DIR/<sample_id>/reflectance.exr and/or shading.exr (linear, any scale), or 16-bit "
            "PNG (value = code / 65535, --png-encoding), optional DIR/<sample_id>/<scenario>/ "
            "for the camera scenarios; see spectrinsic.decompose.evaluation.predictions."
        ),
    )
    _add_folder_options(p)
    _add_method_options(p)
    _add_scoring_options(p)
    p.set_defaults(func=run)


def _add_folder_options(p: Any) -> None:
    """The dataset (or MIT folder) to score and the output folder."""
    p.add_argument(
        "--dataset",
        metavar="DIR",
        default=None,
        help=f"dataset folder built by `spectrinsic dataset` ({DEFAULT_DATASET})",
    )
    p.add_argument(
        "--mit",
        metavar="DIR",
        default=None,
        help="score on an MIT-format folder (<object>.npz, e.g. $SPECTRINSIC_DATA/"
        "mit_intrinsic_dev) with the thesis' protocol and Table 3.2's measures "
        "instead of a rendered dataset; see spectrinsic.decompose.evaluation.mit",
    )
    p.add_argument(
        "--out", metavar="DIR", default=DEFAULT_OUT, help=f"output folder ({DEFAULT_OUT})"
    )


def _add_method_options(p: Any) -> None:
    """The decomposers to run and the prediction folders to read."""
    p.add_argument(
        "--methods",
        default=None,
        help="comma-separated decomposers (default: all registered, plugins included, "
        "or none with --predictions)",
    )
    p.add_argument(
        "--predictions",
        metavar="DIR",
        action="append",
        default=[],
        help="score the estimates in DIR (repeatable); named after the folder unless "
        "given as NAME=DIR",
    )
    p.add_argument(
        "--png-encoding",
        choices=("linear", "srgb"),
        default=None,
        help="encoding of 16-bit PNG predictions (linear)",
    )


def _add_scoring_options(p: Any) -> None:
    """Which samples and target are scored, and what is written besides the scores."""
    p.add_argument(
        "--samples",
        metavar="GLOB",
        default=None,
        help="only samples whose id matches one of these comma-separated patterns (e.g. 'obj-*')",
    )
    p.add_argument(
        "--target",
        choices=TARGETS,
        default=None,
        help="image the methods decompose: the full image, or the diffuse image "
        "(image - specular) of glossy samples (full); see "
        "spectrinsic.decompose.evaluation.targets",
    )
    p.add_argument("--seed", type=int, default=None, help="root seed of the WHDR judgements (0)")
    p.add_argument(
        "--no-cameras",
        action="store_true",
        help="skip the photometric scenarios on camera renderings (Table 5.1)",
    )
    p.add_argument("--no-figures", action="store_true", help="do not draw the per-sample figures")
    p.add_argument("--no-estimates", action="store_true", help="do not write the estimates")


def _methods(args: argparse.Namespace) -> dict[str, Any]:
    encoding: Literal["linear", "srgb"] = "srgb" if args.png_encoding == "srgb" else "linear"
    names = (
        args.methods.split(",")
        if args.methods is not None
        else []
        if args.predictions
        else list(available_decomposers())
    )
    methods: dict[str, Any] = {m.strip(): get_decomposer(m.strip()) for m in names if m.strip()}
    for spec in args.predictions:
        name, sep, folder = spec.partition("=")
        if not sep:
            name, folder = Path(spec).name or "predictions", spec
        elif not name.strip() or not folder.strip():
            raise DatasetError(
                f"--predictions {spec!r}: expected NAME=DIR with a name and a folder"
            )
        if name in methods:
            raise DatasetError(
                f"--predictions {spec!r}: the name {name!r} is already used; "
                f"give another as NAME=DIR"
            )
        methods[name] = Predictions(Path(folder), encoding=encoding, name=name)
    if not methods:
        raise DatasetError("nothing to evaluate: --methods is empty and no --predictions given")
    return methods


def _folders(dataset: Path, patterns: str | None) -> list[Path]:
    if dataset.exists() and (problem := folder_problem(dataset)) is not None:
        raise DatasetError(f"--dataset {str(dataset)!r} {problem}; expected a dataset folder")
    if not dataset.is_dir():
        raise DatasetError(
            f"dataset folder {str(dataset)!r} does not exist; build it first with "
            f"`spectrinsic dataset --out {dataset}` (or `make dataset`; "
            f"`--preset preview` builds a small set in about 2 minutes)"
        )
    # a sample folder (what `relight --out` writes) is scored on its own
    folders = [dataset] if (dataset / "meta.json").is_file() else sample_dirs(dataset)
    if patterns:
        globs = [g.strip() for g in patterns.split(",") if g.strip()]
        folders = [f for f in folders if any(fnmatch.fnmatchcase(f.name, g) for g in globs)]
        if not folders:
            raise DatasetError(f"--samples {patterns!r} matches no sample of {str(dataset)!r}")
    if not folders:
        raise DatasetError(f"dataset folder {str(dataset)!r} holds no complete sample")
    return folders


def _run_mit(args: argparse.Namespace) -> int:
    patterns = [g.strip() for g in args.samples.split(",") if g.strip()] if args.samples else None
    files = mit_folder_objects(Path(args.mit), patterns)
    methods = _methods(args)
    bar = tqdm(total=len(files), desc="evaluate --mit", unit="object", disable=args.quiet)

    def progress(name: str) -> None:
        bar.set_postfix_str(name)
        bar.update(1)

    with staged_output(Path(args.out)) as stage:  # a failed run leaves --out as it was
        try:
            written = evaluate_mit(files, methods, stage, progress=progress)
        finally:
            bar.close()
        with written["table_csv"].open(encoding="utf-8") as table:
            rows = list(csv.DictReader(table))
        write_mit_report(stage, Path(args.mit), len(files), rows)
        print(written["table_md"].read_text(encoding="utf-8"))
    print(
        f"MIT protocol on {len(files)} objects in {args.out} "
        f"(REPORT.md, {MIT_FIGURE}, mit_scores.csv, mit_table_3_2.*)"
    )
    return 0


#: Options of a rendered dataset's evaluation and their defaults: given with --mit, which scores
#: an MIT folder by its own protocol, one is refused in one line instead of ignored.
DATASET_OPTIONS: dict[str, object] = {
    "dataset": DEFAULT_DATASET,
    "target": "full",
    "seed": 0,
    "no_cameras": False,
    "no_figures": False,
    "no_estimates": False,
}


def _check_mode_options(args: argparse.Namespace) -> None:
    """Refuse an option given to a mode it does not apply to (before any folder is read)."""
    if args.png_encoding is not None and not args.predictions:
        raise DatasetError("--png-encoding applies to --predictions (16-bit PNG predictions)")
    for dest, default in DATASET_OPTIONS.items():
        value = getattr(args, dest)
        if args.mit is not None and value not in (None, False):
            raise DatasetError(
                f"--{dest.replace('_', '-')} applies to a rendered dataset; --mit scores an "
                "MIT folder by the thesis' protocol"
            )
        if value is None:
            setattr(args, dest, default)


def run(args: argparse.Namespace) -> int:
    _check_mode_options(args)
    if args.mit is not None:
        return _run_mit(args)
    folders = _folders(Path(args.dataset), args.samples)
    methods = _methods(args)
    check_output_folder(Path(args.out))  # the folder first, as every verb does
    scored = describe_scored(Path(args.dataset), folders)  # refuses a bad sample before work
    with staged_output(Path(args.out)) as stage:  # a failed run leaves --out as it was
        result = _evaluate(args, folders, methods, stage)
        files = write_report(stage, result)  # the tables and REPORT.md, from the scores
        add_scored_section(files["report"], scored)
        for key in ("lmse_by_condition_md", "colour_by_condition_md", "scenario_md"):
            print(files[key].read_text(encoding="utf-8"))
    written = ["REPORT.md with every table and summary.png", "scored.json", "scores.csv"]
    written += [] if args.no_figures else ["figures/"]
    written += [] if args.no_estimates else ["estimates/"]
    print(
        f"{len(result.scores)} scores for {len(folders)} samples in {args.out} ({', '.join(written)})"
    )
    if scored.preview_grade:
        log.warning("%s: preview-grade renderings; REPORT.md says so", args.dataset)
    return 0


def _evaluate(
    args: argparse.Namespace, folders: list[Path], methods: dict[str, Any], out: Path
) -> EvaluationResult:
    """Score every sample with a progress bar; return the evaluation result."""
    bar = tqdm(total=len(folders), desc="evaluate", unit="sample", disable=args.quiet)

    def progress(sample_id: str) -> None:
        bar.set_postfix_str(sample_id)
        bar.update(1)

    try:
        result = evaluate(
            (load_sample(f, space="srgb") for f in folders),  # scored in linear sRGB
            out,
            methods=methods,
            seed=args.seed,
            cameras=not args.no_cameras,
            figures=not args.no_figures,
            save_estimates=not args.no_estimates,
            progress=progress,
            target=args.target,
        )
    finally:
        bar.close()
    return result
