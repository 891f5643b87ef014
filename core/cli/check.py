"""``spectrinsic check DIR``: verify a built dataset (files, layers, values, identities, hashes)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from tqdm import tqdm

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import check_dataset, sample_dirs
from spectrinsic.gt_export.check import NOISE_THRESHOLD, noise_report

__all__ = ["register", "run"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "check",
        help="verify a built dataset: files and layers present, no NaN/Inf or forbidden "
        "negatives, image = reflectance * shading + residual, manifest hashes; report noise",
        description="Verify a built dataset and report each sample's measured Monte Carlo noise "
        "(relative standard error from independent batches). Exit status 1 when a check fails "
        "or a sample is noisier than --noise-threshold.",
    )
    p.add_argument("dir", metavar="DIR", help="dataset folder (with manifest.json)")
    p.add_argument(
        "--max-per-sample", type=int, default=20, metavar="N",
        help="list at most N problems per sample (default 20)",
    )
    p.add_argument(
        "--noise-threshold", type=float, default=None, metavar="F",
        help="flag samples whose raw shading has a median relative standard error above F "
        "(default 0.25)",
    )
    p.add_argument("--noise", action="store_true", help="print every sample's noise figures")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Print problems grouped per sample; exit status 0 when the set is sound, 1 otherwise."""
    if args.noise_threshold is not None and not (math.isfinite(args.noise_threshold) and args.noise_threshold > 0):
        raise DatasetError(f"--noise-threshold {args.noise_threshold}; expected a positive finite "
                           "relative error, e.g. 0.25")
    if args.max_per_sample < 0:
        raise DatasetError(f"--max-per-sample {args.max_per_sample}; expected a whole number >= 0")
    root = Path(args.dir)
    if not root.is_dir():
        raise DatasetError(f"check {str(root)!r}: no such folder; expected a dataset folder")
    n_samples = len(sample_dirs(root))
    with tqdm(total=n_samples, desc="checking", unit="sample", disable=args.quiet or None,
              leave=False) as bar:
        problems = check_dataset(root, progress=lambda _sample: bar.update(1))
    if n_samples:
        threshold = NOISE_THRESHOLD if args.noise_threshold is None else args.noise_threshold
        lines, flagged = noise_report(root, threshold=threshold)
        for line in lines if args.noise else [x for x in lines if "NOISY" in x]:
            print(f"noise: {line}")
        problems += [f"{s}: noisier than the threshold ({threshold:g} median shading error)"
                     for s in flagged]
    if not problems:
        print(f"ok: {n_samples} samples in {root} passed every check")
        return 0
    grouped: dict[str, list[str]] = {}
    for line in problems:
        sample, _, message = line.partition(": ")
        grouped.setdefault(sample, []).append(message)
    for sample, messages in grouped.items():
        print(f"{sample}: {len(messages)} problem(s)")
        for message in messages[: args.max_per_sample]:
            print(f"  - {message}")
        if len(messages) > args.max_per_sample:
            print(f"  ... and {len(messages) - args.max_per_sample} more")
    print(f"spectrinsic check: {len(problems)} problem(s) in {root}", file=sys.stderr)
    return 1
