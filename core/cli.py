"""The ``spectrinsic`` command line. The only place that configures logging and progress bars.

Each sub-command lives in its own ``spectrinsic.cli_<name>`` module exposing
``register(subparsers)``; the module's ``run(args)`` is called with the parsed namespace.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Sequence

from spectrinsic.errors import SpectrinsicError

__all__ = ["main", "build_parser"]

#: Sub-command modules, in the order ``--help`` lists them.
_COMMANDS: tuple[str, ...] = (
    "spectrinsic.cli_info",
    "spectrinsic.cli_render",
    "spectrinsic.cli_dataset",
    "spectrinsic.cli_check",
    "spectrinsic.cli_study",
    "spectrinsic.cli_evaluate",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="spectrinsic",
        description="Spectral rendering of synthetic intrinsic-image datasets.",
    )
    parser.add_argument(
        "--data-dir",
        metavar="DIR",
        default=None,
        help="spectral data directory (SFU set, extra cameras); default: $SPECTRINSIC_DATA",
    )
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more logging")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress bars")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in _COMMANDS:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point. Returns the process exit status (0 ok, 2 bad input)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.WARNING - 10 * min(args.verbose, 2),
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        return int(args.func(args) or 0)
    except SpectrinsicError as exc:
        print(f"spectrinsic: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("spectrinsic: interrupted; completed work is kept, re-run to resume", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
