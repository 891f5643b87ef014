"""``spectrinsic check DIR``: verify a built dataset (files, layers, values, identities, hashes)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from tqdm import tqdm

from ..errors import DatasetError
from ..gt_export import check_dataset, sample_dirs
from ..gt_export.dataset.check import (
    NOISE_THRESHOLD,
    TARGET_MISSED,
    check_sample,
    noise_report,
    residual_share_problems,
    sample_share_problem,
)
from ..gt_export.sample import META_NAME
from ..path_kinds import folder_problem
from .problems import problem_lines

__all__ = ["register", "run"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "check",
        help="verify a built dataset or a sample folder: files and layers present, no NaN/Inf or forbidden "
        "negatives, image = reflectance * shading + residual, manifest hashes; report noise",
        description="Verify a built dataset and report each sample's measured Monte Carlo noise "
        "(relative standard error from independent batches). Exit status 1 when a check fails, "
        "a sample misses the noise_target its build promised, or, with --noise-threshold, a "
        "sample is noisier than it. Without --noise-threshold, samples above the default "
        "threshold are counted in one warning line: a preset without a noise_target (preview) "
        "promises a look at the layout, not training data. A problem shared by several samples "
        "is printed once with their count.",
    )
    p.add_argument(
        "dir",
        metavar="DIR",
        help="dataset folder (with manifest.json), or one sample folder (with meta.json, "
        "e.g. what `relight --out` writes: its files, layers, values, identities and hashes)",
    )
    p.add_argument(
        "--max-per-sample",
        type=int,
        default=20,
        metavar="N",
        help="list at most N problems per sample (default 20)",
    )
    p.add_argument(
        "--noise-threshold",
        type=float,
        default=None,
        metavar="F",
        help="fail on samples whose raw shading has a median relative standard error above F "
        "(default: warn above 0.25, fail only on a missed noise_target)",
    )
    p.add_argument("--noise", action="store_true", help="print every sample's noise figures")
    p.add_argument(
        "--max-residual-share",
        type=float,
        default=None,
        metavar="F",
        help="fail on samples whose RGB residual holds more than the fraction F of the image "
        "(sum |residual| / sum |image| over the mask, meta.json residual_share), e.g. 0.05",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Print problems grouped per sample; exit status 0 when the set is sound, 1 otherwise."""
    if args.noise_threshold is not None and not (
        math.isfinite(args.noise_threshold) and args.noise_threshold > 0
    ):
        raise DatasetError(
            f"--noise-threshold {args.noise_threshold}; expected a positive finite "
            "relative error, e.g. 0.25"
        )
    share = getattr(args, "max_residual_share", None)
    if share is not None and not (math.isfinite(share) and share >= 0):
        raise DatasetError(
            f"--max-residual-share {share}; expected a fraction >= 0 of the image, e.g. 0.05"
        )
    if args.max_per_sample < 0:
        raise DatasetError(f"--max-per-sample {args.max_per_sample}; expected a whole number >= 0")
    root = Path(args.dir)
    if (problem := folder_problem(root)) is not None:
        raise DatasetError(
            f"check {str(root)!r} {problem}; expected a dataset folder or a sample folder"
        )
    if (root / META_NAME).is_file():  # one sample folder, e.g. what `relight --out` writes
        problems = [f"{root.name}: {p}" for p in check_sample(root)]
        if share is not None and (problem := sample_share_problem(root, share)) is not None:
            problems.append(problem)
        return _report(problems, root, 1, args)
    n_samples = len(sample_dirs(root))
    with tqdm(
        total=n_samples, desc="checking", unit="sample", disable=args.quiet or None, leave=False
    ) as bar:
        problems = check_dataset(root, progress=lambda _sample: bar.update(1))
    if n_samples:
        problems += _noise_problems(root, args.noise_threshold, n_samples, verbose=args.noise)
    if n_samples and share is not None:
        problems += residual_share_problems(root, share)
    return _report(problems, root, n_samples, args)


def _report(problems: list[str], root: Path, n_samples: int, args: argparse.Namespace) -> int:
    """Print *problems* grouped per sample, or the ok line; the exit status."""
    if not problems:
        what = "1 sample" if n_samples == 1 else f"{n_samples} samples"
        print(f"ok: {what} in {root} passed every check")
        return 0
    for line in problem_lines(problems, max_per_sample=args.max_per_sample):
        print(line)
    print(f"spectrinsic check: {len(problems)} problem(s) in {root}", file=sys.stderr)
    return 1


def _noise_problems(
    root: Path, threshold: float | None, n_samples: int, *, verbose: bool
) -> list[str]:
    """Noise problems: a missed ``noise_target`` always, samples above *threshold* when one was
    given; above the default threshold otherwise only one warning line on stderr."""

    lines, flagged = noise_report(
        root, threshold=NOISE_THRESHOLD if threshold is None else threshold
    )
    for line in lines if verbose else []:
        print(f"noise: {line}")
    problems = [
        f"{line.partition(': ')[0]}: {TARGET_MISSED.lower()}{line.partition(TARGET_MISSED)[2]}"
        for line in lines
        if TARGET_MISSED in line
    ]
    if threshold is not None:
        return problems + [
            f"{s}: noisier than --noise-threshold {threshold:g} (median relative "
            "standard error of the raw shading)"
            for s in flagged
        ]
    if flagged:
        print(
            f"spectrinsic check: warning: {len(flagged)} of {n_samples} samples have raw shading "
            f"noisier than {NOISE_THRESHOLD:g} (median relative standard error; --noise lists "
            "them). Their build promised no noise level: a look at the layout, not training "
            "data. Build with --preset default or --noise-target F for training data; pass "
            "--noise-threshold F to fail on it.",
            file=sys.stderr,
        )
    return problems
