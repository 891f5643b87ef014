"""``spectrinsic evaluate``: run the bundled decomposers on a rendered dataset and score them."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path
from typing import Any

from spectrinsic.errors import DatasetError

__all__ = ["register", "run", "DEFAULT_DATASET", "DEFAULT_OUT"]

DEFAULT_DATASET = "data/dataset"
DEFAULT_OUT = "results/evaluation"

log = logging.getLogger(__name__)


def register(subparsers: Any) -> None:
    from spectrinsic.decompose.registry import DECOMPOSERS

    p = subparsers.add_parser(
        "evaluate",
        help="score the bundled decomposers on a rendered dataset (thesis Tables 5.1, 5.3, 5.4)",
        description=(
            "Decompose every sample of a dataset with each method, score reflectance and "
            "shading (LMSE, aLMSE, MSE, correlation, DSSIM, angular error, WHDR), and write "
            "scores.csv, the tables like Tables 5.3/5.4 and 5.1 (markdown + CSV), a figure per "
            "sample and every estimate as EXR."
        ),
    )
    p.add_argument("--dataset", metavar="DIR", default=DEFAULT_DATASET,
                   help=f"dataset folder built by `spectrinsic dataset` ({DEFAULT_DATASET})")
    p.add_argument("--out", metavar="DIR", default=DEFAULT_OUT, help=f"output folder ({DEFAULT_OUT})")
    p.add_argument("--methods", default=",".join(DECOMPOSERS),
                   help="comma-separated decomposers (default: all: %(default)s)")
    p.add_argument("--seed", type=int, default=0, help="root seed of the WHDR judgements (0)")
    p.add_argument("--no-cameras", action="store_true",
                   help="skip the photometric scenarios on camera renderings (Table 5.1)")
    p.add_argument("--no-figures", action="store_true", help="do not draw the per-sample figures")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from spectrinsic.decompose.evaluate import evaluate
    from spectrinsic.decompose.registry import get_decomposer

    dataset = Path(args.dataset)
    if not dataset.is_dir():
        raise DatasetError(
            f"dataset folder {str(dataset)!r} does not exist; build it first with "
            f"`spectrinsic dataset --out {dataset}` (or `make dataset`; "
            f"`--preset preview` builds a small set in about 2 minutes)"
        )
    from spectrinsic.gt_export.writer import sample_dirs

    folders = sample_dirs(dataset)
    if not folders:
        raise DatasetError(f"dataset folder {str(dataset)!r} holds no complete sample")
    methods = {m: get_decomposer(m.strip()) for m in args.methods.split(",") if m.strip()}

    from tqdm import tqdm

    from spectrinsic.gt_export.loader import load_sample

    bar = tqdm(total=len(folders), desc="evaluate", unit="sample", disable=args.quiet)

    def progress(sample_id: str) -> None:
        bar.set_postfix_str(sample_id)
        bar.update(1)

    try:
        result = evaluate(
            (load_sample(f) for f in folders), args.out, methods=methods, seed=args.seed,
            cameras=not args.no_cameras, figures=not args.no_figures,
            progress=progress,
        )
    finally:
        bar.close()
    for key in ("condition_md", "scenario_md"):
        print(result.files[key].read_text(encoding="utf-8"))
    print(f"{len(result.scores)} scores for {len(folders)} samples in {args.out} "
          f"(scores.csv, tables, figures/, estimates/)")
    return 0
