"""``spectrinsic export DIR --out SHARDS``: a built dataset as WebDataset tar shards."""

from __future__ import annotations

import argparse
from pathlib import Path

from tqdm import tqdm

from ..errors import DatasetError
from ..gt_export import sample_dirs
from ..gt_export.dataset.shards import check_export_source, check_shard_folder, write_shards
from ..gt_export.sample import MANIFEST_NAME

__all__ = ["register", "run"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export",
        help="write a built dataset as WebDataset tar shards, one set per split",
        description="Write the complete samples of a built dataset as WebDataset tar shards "
        "(<split>-000000.tar ...; every layer as .npy, meta.json beside it) plus shards.json, "
        "for streaming training on large sets. Splits follow the manifest (by scene). The same "
        "dataset gives byte-identical shards; the index is written last, so an interrupted "
        "export is never taken for a complete one, and re-running it finishes it.",
    )
    p.add_argument("dir", metavar="DIR", help="dataset folder (with manifest.json)")
    p.add_argument(
        "--out", required=True, metavar="DIR", help="shard folder: new, empty, or an earlier export"
    )
    p.add_argument(
        "--samples-per-shard",
        type=int,
        default=1000,
        metavar="N",
        help="most samples in one shard (default 1000)",
    )
    p.add_argument(
        "--layers",
        default=None,
        metavar="KEYS",
        help="comma-separated layer keys to keep (default: every layer)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Write the shards with a progress bar; print where they are and how many samples each split has."""
    root = Path(args.dir)
    if not (root / MANIFEST_NAME).is_file():
        raise DatasetError(
            f"export {str(root)!r}: no {MANIFEST_NAME}; expected a built dataset folder"
        )
    check_export_source(root)  # whole and held by no build: never a partial export
    check_shard_folder(Path(args.out))  # before the progress bar: new, empty or an earlier export
    layers = None if args.layers is None else [k.strip() for k in args.layers.split(",")]
    if layers is not None and not all(layers):
        raise DatasetError(
            f"--layers {args.layers!r}: expected comma-separated layer keys, e.g. image,shading"
        )
    with tqdm(
        total=len(sample_dirs(root)),
        desc="exporting",
        unit="sample",
        disable=args.quiet or None,
        leave=False,
    ) as bar:
        written = write_shards(
            root,
            args.out,
            samples_per_shard=args.samples_per_shard,
            layers=layers,
            progress=lambda _sid: bar.update(1),
        )
    counts = ", ".join(
        f"{split} {n} in {len(written.shards[split])} shard(s)"
        for split, n in written.samples.items()
    )
    print(f"shards: {written.folder} ({counts}); index {written.folder / 'shards.json'}")
    return 0
