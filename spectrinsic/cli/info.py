"""``spectrinsic info``: versions, usable Mitsuba variants, data directories."""

from __future__ import annotations

import argparse
from typing import Any

from ..data_dir import DATA_SUBDIRS, resolve_data_dir
from ..provenance import DISTRIBUTIONS, software_versions
from ..render.base.variants import available_variants, llvm_library

__all__ = ["register", "run", "collect_info"]

#: What ``info`` reports: the provenance set plus the optional extras.
_DISTRIBUTIONS = (*DISTRIBUTIONS, "bpy", "distributed")


def collect_info(data_dir: str | None = None) -> dict[str, Any]:
    """Everything ``info`` prints, as plain data (also recorded in dataset manifests)."""
    versions = software_versions(_DISTRIBUTIONS, python=False)

    root = resolve_data_dir(data_dir)
    found = {} if root is None else {k: (root / k).is_dir() for k in DATA_SUBDIRS}
    return {
        "python": software_versions((), python=True)["python"],
        "versions": versions,
        "llvm_library": llvm_library(),
        "variants": available_variants(),
        "data_dir": None if root is None else str(root),
        "data_subdirs": found,
    }


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "info",
        help="versions, usable Mitsuba variants, data directories",
        description="Print the installed versions of spectrinsic and the libraries that compute "
        "its pixels, the Mitsuba variants usable here (cuda > llvm > scalar) and the libLLVM "
        "Dr.Jit uses, and the spectral data directory found (--data-dir, $SPECTRINSIC_DATA or "
        "../shared/data through make) with its subfolders.",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    info = collect_info(args.data_dir)
    print(f"spectrinsic {info['versions']['spectrinsic']} on Python {info['python']}")
    for dist, ver in info["versions"].items():  # type: ignore[union-attr]
        if dist != "spectrinsic":
            print(f"  {dist:<14} {ver}")
    print(f"LLVM for Dr.Jit: {info['llvm_library'] or 'none found (scalar variants only)'}")
    print("Mitsuba variants usable here: " + ", ".join(info["variants"]))  # type: ignore[arg-type]
    if info["data_dir"] is None:
        print("data directory: none (set SPECTRINSIC_DATA or --data-dir for SFU and extra cameras)")
    else:
        print(f"data directory: {info['data_dir']}")
        for sub, ok in info["data_subdirs"].items():  # type: ignore[union-attr]
            print(f"  {'found  ' if ok else 'missing'} {sub}: {DATA_SUBDIRS[sub]}")
    return 0
