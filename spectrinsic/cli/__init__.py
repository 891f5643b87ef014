"""The ``spectrinsic`` command line. The only place that configures logging and progress bars.

Each sub-command lives in its own ``spectrinsic.cli.<name>`` module exposing
``register(subparsers)``; the module's ``run(args)`` is called with the parsed namespace.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import logging
import re
import sys
import traceback
import warnings
from collections.abc import Iterator, Sequence
from typing import Any, NoReturn, TextIO

from ..data_dir import one_data_dir
from ..errors import SpectrinsicError, did_you_mean
from ..interrupts import exit_status, interrupts_reach_python
from ..provenance import software_versions

__all__ = ["main", "build_parser"]

log = logging.getLogger(__name__)

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
    "spectrinsic.cli.train",
    "spectrinsic.cli.list",
)


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (``spectrinsic: error: ...``, status 2),
    like every other bad input; ``--help`` still prints the usage. Sub-command parsers are of
    this class too (``add_subparsers`` makes them with the parent's class). :attr:`verbs`:
    the top-level parser's sub-command parsers by name."""

    verbs: dict[str, argparse.ArgumentParser]

    def error(self, message: str) -> NoReturn:
        where = self.prog.removeprefix("spectrinsic").strip()
        text = " ".join(message.split()) + _choice_hint(message)
        self.exit(
            2,
            f"spectrinsic: error: {where + ': ' if where else ''}{text} (see {self.prog} --help)\n",
        )


def _choice_hint(message: str) -> str:
    """A suggestion for argparse's ``invalid choice: 'rendr' (choose from 'info', ...)``: a
    mistyped verb, study or preset (Python 3.11's argparse suggests nothing)."""
    found = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)", message)
    return did_you_mean(found[1], re.findall(r"'([^']*)'", found[2])) if found else ""


def _unrecognized(parser: _Parser, verb: str | None, extras: list[str]) -> NoReturn:
    """Refuse arguments no parser took, by the verb's parser (so the line names the verb and
    its ``--help``) and with the verb's closest option for each mistyped one."""
    by = parser.verbs.get(verb or "", parser)
    options = sorted(set(re.findall(r"--[a-z][\w-]*", by.format_usage())))
    hints = "".join(
        did_you_mean(e.split("=", 1)[0], options, n=2) for e in extras if e.startswith("--")
    )
    by.error(f"unrecognized arguments: {' '.join(extras)}{hints}")


def build_parser() -> _Parser:
    parser = _Parser(
        prog="spectrinsic",
        description="Spectral rendering of synthetic intrinsic-image datasets.",
    )
    _add_global_options(parser)
    parser.add_argument("--version", action="version", version=f"spectrinsic {_version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in _COMMANDS:
        importlib.import_module(name).register(sub)
    parser.verbs = dict(sub.choices)
    for command in sub.choices.values():  # the global options work after the verb too
        _add_global_options(command.add_argument_group("global options"), after_verb=True)
    return parser


def _add_global_options(p: Any, *, after_verb: bool = False) -> None:
    """--data-dir, -v, -q, --debug: before the verb with their defaults; after it (on every
    sub-command) without defaults (``SUPPRESS``), so a flag given there is set and one not
    given keeps what the top-level parser set."""

    def default(value: Any) -> Any:
        return argparse.SUPPRESS if after_verb else value

    p.add_argument(
        "--data-dir",
        metavar="DIR",
        default=default(None),
        help="spectral data directory (SFU set, extra cameras); default: $SPECTRINSIC_DATA",
    )
    p.add_argument("-v", "--verbose", action="count", default=default(0), help="more logging")
    p.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        default=default(False),
        help="no progress bars or plan lines",
    )
    p.add_argument(
        "--debug",
        action="store_true",
        default=default(False),
        help="print the traceback behind an error message",
    )


def _version() -> str:
    """spectrinsic's installed version, from package metadata (nothing heavy imported)."""

    return software_versions(("spectrinsic",), python=False)["spectrinsic"]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point. Returns the process exit status (0 ok, 1 problems found or samples failed,
    2 bad input or a resource that failed: one line on stderr, the traceback only with
    ``--debug``; 130 interrupted, 143 stopped by SIGTERM)."""
    # Before anything starts a thread: Ctrl-C must reach Python even mid-render.
    with interrupts_reach_python():
        try:
            return _main(argv)
        except KeyboardInterrupt:  # Ctrl-C, or SIGTERM (spectrinsic.interrupts), even at start
            print(
                "spectrinsic: interrupted; completed work is kept, re-run to resume",
                file=sys.stderr,
            )
            return exit_status()


def _main(argv: Sequence[str] | None) -> int:
    parser = build_parser()
    args, extras = parser.parse_known_args(argv)
    if extras:
        _unrecognized(parser, getattr(args, "command", None), extras)
    logging.basicConfig(
        level=logging.WARNING - 10 * min(args.verbose, 2),
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        # one data directory for the whole run (--data-dir, else $SPECTRINSIC_DATA), resolved
        # once, before any work (a wrong one is an input error), and seen by every worker
        with one_data_dir(args.data_dir) as data_dir, _arithmetic_warnings_logged():
            args.data_dir = data_dir
            return int(args.func(args) or 0)
    except SpectrinsicError as exc:
        return _error(args, str(exc))
    except OSError as exc:  # a file the command could not read or write, named by the OS
        where = f"{exc.filename}: " if exc.filename else ""
        return _error(args, f"{where}{exc.strerror or exc}")
    except MemoryError:
        return _error(
            args, "out of memory; try a smaller --resolution/--width/--height or fewer --workers"
        )


@contextlib.contextmanager
def _arithmetic_warnings_logged() -> Iterator[None]:
    """numpy's arithmetic ``RuntimeWarning`` (overflow, invalid value: ``relight --power 1e20``,
    a NaN in a mesh file) go to the debug log (``-vv``) instead of stderr. Every result is
    checked finite before it is written and every bad input is refused in one line that says
    what was wrong, so the warning only added lines before that one line. spectrinsic's own
    warnings (:class:`~spectrinsic.errors.SpectrinsicWarning`) are shown as before."""
    shown = warnings.showwarning

    def show(message: Warning | str, category: type[Warning], filename: str, lineno: int,
             file: TextIO | None = None, line: str | None = None) -> None:  # fmt: skip
        if issubclass(category, RuntimeWarning):
            log.debug("%s:%d: %s: %s", filename, lineno, category.__name__, message)
        else:
            shown(message, category, filename, lineno, file, line)

    with warnings.catch_warnings():
        warnings.showwarning = show
        yield


def _error(args: argparse.Namespace, message: str) -> int:
    """Print the one-line error (after the traceback with ``--debug``); return status 2."""
    if getattr(args, "debug", False):
        traceback.print_exc()
    print(f"spectrinsic: error: {' '.join(message.split())}", file=sys.stderr)
    return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
