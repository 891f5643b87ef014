"""Shared fixtures: the spectral data directory and the repository root."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]


def _data_dir() -> Path | None:
    env = os.environ.get("SPECTRINSIC_DATA", "").strip()
    candidates = [Path(env)] if env else []
    candidates.append(REPO_ROOT.parent / "shared" / "data")
    for c in candidates:
        if (c / "sfu_barnard2002").is_dir():
            return c.resolve()
    return None


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return REPO_ROOT


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The spectral data directory (../shared/data in CI); tests needing it skip with a reason."""
    path = _data_dir()
    if path is None:
        pytest.skip("no spectral data directory: set SPECTRINSIC_DATA or place ../shared/data")
    return path


@pytest.fixture(scope="session")
def torch():
    """PyTorch for the adapter tests. ``make test-torch`` (run by CI) installs it and sets
    ``SPECTRINSIC_REQUIRE_TORCH=1``, so there a missing torch fails instead of skipping."""
    if os.environ.get("SPECTRINSIC_REQUIRE_TORCH") == "1":
        import torch

        return torch
    return pytest.importorskip("torch", reason="PyTorch is an optional extra: make test-torch installs it")
