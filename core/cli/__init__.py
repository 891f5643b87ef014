"""The ``spectrinsic`` command line. The only place that configures logging and progress bars.

Each sub-command lives in its own ``spectrinsic.cli.<name>`` module exposing
``register(subparsers)``; the module's ``run(args)`` is called with the parsed namespace.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
import traceback
from collections.abc import Sequence

from spectrinsic.errors import SpectrinsicError

__all__ = ["main", "build_parser"]

#: Sub-command modules, in the order ``--help`` lists them.
_COMMANDS: tuple[str, ...] = (
    "spectrinsic.cli.info",
    "spectrinsic.cli.render",
    "spectrinsic.cli.dataset",
    "spectrinsic.cli.check",
    "spectrinsic.cli.relight",
    "spectrinsic.cli.export",
    "spectrinsic.cli.study",
    "spectrinsic.cli.evaluate",
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
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress bars or plan lines")
    parser.add_argument(
        "--debug", action="store_true", help="print the traceback behind an error message"
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in _COMMANDS:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point. Returns the process exit status (0 ok, 1 problems found or samples failed,
    2 bad input or a resource that failed: one line on stderr, the traceback only with
    ``--debug``)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.WARNING - 10 * min(args.verbose, 2),
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        return int(args.func(args) or 0)
    except SpectrinsicError as exc:
        return _error(args, str(exc))
    except OSError as exc:  # a file the command could not read or write, named by the OS
        where = f"{exc.filename}: " if exc.filename else ""
        return _error(args, f"{where}{exc.strerror or exc}")
    except MemoryError:
        return _error(args, "out of memory; try a smaller --resolution/--width/--height or fewer --workers")
    except KeyboardInterrupt:
        print("spectrinsic: interrupted; completed work is kept, re-run to resume", file=sys.stderr)
        return 130


def _error(args: argparse.Namespace, message: str) -> int:
    """Print the one-line error (after the traceback with ``--debug``); return status 2."""
    if getattr(args, "debug", False):
        traceback.print_exc()
    print(f"spectrinsic: error: {' '.join(message.split())}", file=sys.stderr)
    return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
