from __future__ import annotations

import os
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The spectral data directory: $SPECTRINSIC_DATA, else ../shared/data next to the repo."""
    env = os.environ.get("SPECTRINSIC_DATA", "").strip()
    path = Path(env) if env else Path(__file__).resolve().parents[3] / "shared" / "data"
    if not (path / "colour_naming_benavente2008_tse").is_dir():
        pytest.skip(f"no data directory with colour_naming_benavente2008_tse at {path}")
    return path
