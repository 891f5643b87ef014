"""``spectrinsic dataset --variant``: which Mitsuba backend renders the samples (cuda on a GPU,
llvm on CPUs), as ``render --variant`` chooses it for one render."""

from __future__ import annotations

import argparse
from typing import Any

from ..render.base.variants import choose_variant

__all__ = ["add_variant_option", "check_variant"]


def add_variant_option(p: Any) -> None:
    """Add ``--variant`` (recorded in the config as ``variant``)."""
    p.add_argument(
        "--variant",
        default=None,
        metavar="BACKEND",
        help="Mitsuba backend (cuda, llvm, scalar) or variant name that renders every sample "
        "(default: the best usable where it renders: cuda > llvm > scalar); checked here "
        "before any work, unless --scheduler renders elsewhere",
    )


def check_variant(args: argparse.Namespace) -> None:
    """Refuse an unknown or (here) unusable backend before any work (one line, rc 2)."""
    variant = getattr(args, "variant", None)
    if variant is not None and not getattr(args, "scheduler", None):
        choose_variant("rgb", variant)
