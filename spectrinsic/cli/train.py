"""``spectrinsic train``: the reference U-Net trained on a built dataset (:mod:`spectrinsic.learn`).

The output folder is new, empty, or one of this verb's own (its ``training.json`` present and
only the files a run writes), held under the folders' lock while it trains.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from tqdm import tqdm

from ..errors import DatasetError
from ..file_writes import write_text_file
from ..gt_export.folders.outfolder import LOCK_NAME, check_out_folder, folder_lock
from ..learn import card
from ..learn.data import TrainLayers, training_folders
from ..learn.torch_import import require_torch
from ..learn.train import CHECKPOINT, TrainOptions, train
from ..path_kinds import folder_problem

__all__ = ["register", "run", "TRAINING_MARKER"]

#: The file that marks a folder as ``spectrinsic train``'s (the options of its run).
TRAINING_MARKER = "training.json"
_FILES = {
    TRAINING_MARKER,
    CHECKPOINT,
    CHECKPOINT + ".tmp",
    card.WEIGHTS,
    card.WEIGHTS + ".tmp",
    card.CURVE_CSV,
    card.CURVE_PNG,
    card.CARD_MD,
    card.CARD_JSON,
    LOCK_NAME,
}


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "train",
        help="train the reference U-Net (log reflectance and shading) on a built dataset",
        description="Train a small U-Net predicting log reflectance and log shading from the "
        "log image (scale-invariant loss of Eigen et al. 2014) on a dataset's train split; "
        "write weights.pt, curve.csv/.png, MODEL.md and model.json into --out. Score it with "
        "`spectrinsic evaluate --methods unet:OUT/weights.pt`. Needs the torch extra.",
    )
    p.add_argument("dataset", type=Path, help="dataset folder built by `spectrinsic dataset`")
    p.add_argument("--out", type=Path, required=True, help="output folder")
    p.add_argument("--steps", type=int, default=2000, help="optimiser steps in all (2000)")
    p.add_argument("--seed", type=int, default=0, help="root seed of weights and batches (0)")
    p.add_argument("--batch", type=int, default=8, help="crops per step (8)")
    p.add_argument("--crop", type=int, default=64, help="side of the random crops, px (64)")
    p.add_argument("--lr", type=float, default=1e-3, help="Adam learning rate (0.001)")
    p.add_argument("--device", choices=("cpu", "cuda"), default="cpu", help="device (cpu)")
    p.add_argument("--resume", action="store_true", help="continue --out's checkpoint")
    p.add_argument(
        "--relight",
        action="store_true",
        help="relight each drawn sample under random light spectra (needs --store-transport)",
    )
    p.add_argument(
        "--layers",
        default="image,reflectance,shading",
        metavar="IMAGE,REFLECTANCE,SHADING",
        help="input and target layers (image,reflectance,shading; e.g. image_rgb3,...)",
    )
    p.add_argument("--samples", metavar="GLOB", default=None, help="only these sample ids")
    p.add_argument("--checkpoint-every", type=int, default=100, help="steps between checkpoints")
    p.set_defaults(func=run)


def _options(args: argparse.Namespace) -> TrainOptions:
    names = [n.strip() for n in args.layers.split(",")]
    if len(names) != 3 or not all(names):
        raise DatasetError(f"--layers {args.layers!r}: expected IMAGE,REFLECTANCE,SHADING")
    for flag in ("steps", "batch", "crop", "checkpoint_every"):
        if getattr(args, flag) < 1:
            raise DatasetError(f"--{flag.replace('_', '-')} {getattr(args, flag)}: expected >= 1")
    if not args.lr > 0:
        raise DatasetError(f"--lr {args.lr}: expected a positive learning rate")
    samples = tuple(g.strip() for g in args.samples.split(",")) if args.samples else None
    return TrainOptions(
        steps=args.steps,
        seed=args.seed,
        batch=args.batch,
        crop=args.crop,
        lr=args.lr,
        layers=TrainLayers(*names),
        samples=samples,
        relight=args.relight,
        checkpoint_every=args.checkpoint_every,
        device=args.device,
    )


def _own(folder: Path) -> bool:
    files = {p.name for p in folder.iterdir()}
    return TRAINING_MARKER in files and files <= _FILES


def _check_out(out: Path, resume: bool) -> None:
    check_out_folder(out, own=_own, what=f"a spectrinsic train folder ({TRAINING_MARKER})")
    if not resume and (out / CHECKPOINT).exists():
        raise DatasetError(
            f"--out {str(out)!r} holds a training checkpoint: add --resume to continue it, "
            "or choose a new folder"
        )


def run(args: argparse.Namespace) -> int:
    options = _options(args)
    if (problem := folder_problem(args.dataset)) is not None:
        raise DatasetError(f"dataset folder {str(args.dataset)!r} {problem}")
    torch = require_torch("spectrinsic train")  # before any folder is made
    if options.device == "cuda" and not torch.cuda.is_available():
        raise DatasetError("--device cuda: this torch sees no CUDA device; use --device cpu")
    training_folders(
        args.dataset, options.split, options.samples, options.layers, relight=options.relight
    )
    _check_out(args.out, args.resume)
    with folder_lock(args.out):
        write_text_file(args.out / TRAINING_MARKER, json.dumps(options.to_dict(), indent=1) + "\n")
        bar = tqdm(
            total=options.steps,
            desc="train",
            unit="step",
            file=sys.stderr,
            disable=bool(getattr(args, "quiet", False)),
        )

        def on_step(step: int, loss: float) -> None:
            bar.n = step
            bar.set_postfix(loss=f"{loss:.4f}", refresh=False)
            bar.update(0)

        try:
            result = train(args.dataset, args.out, options, resume=args.resume, on_step=on_step)
        finally:
            bar.close()
        paths = card.write_outputs(args.out, args.dataset, options, result)
    final = result.curve[-1][1] if result.curve else float("nan")
    print(
        f"trained {options.steps} steps on {len(result.folders)} samples in "
        f"{result.seconds:.1f} s (final loss {final:.4f})"
    )
    for path in paths.values():
        print(f"wrote {path}")
    return 0
