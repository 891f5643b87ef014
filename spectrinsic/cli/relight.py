"""``spectrinsic relight SAMPLE --light 0=planck:3000K --out DIR``: a sample under new lights.

The sample must store its per-light transport (``spectrinsic dataset --store-transport``);
:func:`spectrinsic.gt_export.relight.relight` writes the relit sample, every layer exact.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ..errors import DatasetError, SpectrinsicError
from ..gt_export.folders.outfolder import check_out_folder, check_unlocked, folder_lock
from ..gt_export.relight import relight
from ..gt_export.sample.meta import owned_files
from ..spectra.user_spectra import absolute_csv

__all__ = ["register", "run", "parse_assignments"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "relight",
        help="relight a sample stored with --store-transport under new light spectra (exact)",
        description="Write SAMPLE under new light spectra as a complete sample folder --out: "
        "image, shading, residual, illuminant, light shares, camera layers and noise, "
        "all recomputed from the per-light transport the sample stores (build it with "
        "`spectrinsic dataset --store-transport`). Spectra are registry names "
        "(planck:3000K, daylight:5000K, cie:LED-RGB1, cie:FL11, ...). --out must be a "
        "new or empty folder, or a sample spectrinsic wrote, outside any dataset; "
        "nothing else is replaced. The folder holding --out is locked while it is written.",
    )
    p.add_argument(
        "sample", metavar="SAMPLE", help="sample folder (with meta.json and transport.exr)"
    )
    p.add_argument(
        "--light",
        action="append",
        default=[],
        metavar="INDEX=SPECTRUM",
        required=True,
        help="light INDEX (meta.json lights[INDEX]) gets SPECTRUM; repeat per light",
    )
    p.add_argument(
        "--power",
        action="append",
        default=[],
        metavar="INDEX=POWER",
        help="also scale light INDEX to POWER (default: its own power)",
    )
    p.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="the relit sample folder to write"
    )
    p.add_argument(
        "--scene-dir",
        type=Path,
        metavar="DIR",
        help="the folder of the scene file the sample was built from: a sample names its "
        "csv: spectra relative to it (no path of the building machine is recorded), and they "
        "are read and checked against their SHA-256 there; needed only for such samples",
    )
    p.add_argument(
        "--keep-transport",
        action="store_true",
        help="store the transport in the relit sample too (so it can be relit itself)",
    )
    p.set_defaults(func=run)


def parse_assignments(
    values: list[str], option: str, *, number: bool = False
) -> dict[int, str | float]:
    """``["0=planck:3000K", ...]`` -> ``{0: "planck:3000K"}`` (floats with *number*); a one-line
    error naming the option for anything else."""
    out: dict[int, str | float] = {}
    for text in values:
        index, sep, value = text.partition("=")
        if not sep or not index.strip().isdigit() or not value.strip():
            raise DatasetError(
                f"{option} {text!r}: expected INDEX=VALUE, e.g. {option} 0=planck:3000K"
                if not number
                else f"{option} {text!r}: expected INDEX=NUMBER, e.g. {option} 0=2.5"
            )
        key = int(index)
        if key in out:
            raise DatasetError(f"{option} {text!r}: light {key} is given twice")
        if number:
            try:
                out[key] = float(value)
            except ValueError:
                raise DatasetError(f"{option} {text!r}: {value!r} is not a number") from None
        else:
            try:
                out[key] = absolute_csv(value.strip())
            except SpectrinsicError as exc:
                raise DatasetError(f"{option} {text!r}: {exc}") from None
    return out


def run(args: argparse.Namespace) -> int:
    lights = parse_assignments(args.light, "--light")
    powers = parse_assignments(args.power, "--power", number=True)
    sample = Path(args.sample)
    if not sample.is_dir():
        raise DatasetError(f"SAMPLE {str(sample)!r} is not a folder; expected a sample folder")
    if args.scene_dir is not None and not args.scene_dir.is_dir():
        raise DatasetError(
            f"--scene-dir {str(args.scene_dir)!r} is not a folder; expected the folder of the "
            "scene file the sample was built from"
        )
    # the --out rule of every writing verb: new, empty or a sample spectrinsic wrote
    check_out_folder(
        args.out, own=lambda p: owned_files(p) is not None, what="a sample folder spectrinsic wrote"
    )
    # the lock is on the folder that receives the sample: the sample folder itself is
    # replaced whole (a new folder renamed over it), so it cannot hold a lock file
    parent = args.out.absolute().parent
    check_unlocked(parent)
    start = time.perf_counter()
    with folder_lock(parent):
        out = relight(
            sample,
            lights,  # type: ignore[arg-type]
            args.out,
            powers=powers,  # type: ignore[arg-type]
            data_dir=args.data_dir,
            keep_transport=args.keep_transport,
            scene_dir=args.scene_dir,
        )
    if not args.quiet:
        print(
            f"spectrinsic relight: wrote {out} in {time.perf_counter() - start:.2f} s",
            file=sys.stderr,
        )
    print(out)
    return 0
