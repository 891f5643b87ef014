"""Provenance of every output: installed software versions and the git commit.

A leaf module (standard library only) so every package may record provenance.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterable
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

__all__ = ["DISTRIBUTIONS", "software_versions", "git_commit", "provenance"]

#: Distributions whose versions shape spectrinsic's outputs.
DISTRIBUTIONS: tuple[str, ...] = (
    "spectrinsic",
    "numpy",
    "scipy",
    "colour-science",
    "luxpy",
    "mitsuba",
    "drjit",
    "OpenEXR",
    "trimesh",
    "scikit-image",
    "gco-wrapper",
    "matplotlib",
    "pillow",
)


def software_versions(
    distributions: Iterable[str] = DISTRIBUTIONS, *, python: bool = True
) -> dict[str, str]:
    """Installed version of each distribution (``"absent"`` when not installed), from package
    metadata so nothing heavy (Mitsuba) is imported; plus the Python version if *python*."""
    out = {"python": sys.version.split()[0]} if python else {}
    for dist in distributions:
        try:
            out[dist] = version(dist)
        except PackageNotFoundError:
            out[dist] = "absent"
    return out


def git_commit() -> str | None:
    """The commit of the source tree spectrinsic runs from, or None outside a git checkout."""
    try:
        sha = subprocess.run(
            ["git", "rev-parse", "HEAD"],
            cwd=Path(__file__).resolve().parent,
            capture_output=True,
            text=True,
            timeout=5,
            check=False,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return sha or None


def provenance() -> dict[str, Any]:
    """``{"software": software_versions(), "git_sha": git_commit()}``."""
    return {"software": software_versions(), "git_sha": git_commit()}
