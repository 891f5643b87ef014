"""The extras the README names exist (issue 31): dask-jobqueue for SLURM, torch for the
DataLoader examples."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_cluster_extra_declares_dask_jobqueue_and_the_readme_names_it():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"
    ]
    assert any(d.startswith("dask-jobqueue") for d in extras["cluster"])
    assert any(d.startswith("torch") for d in extras["torch"])
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "pip install 'spectrinsic[cluster]'" in readme
    assert "pip install 'spectrinsic[torch]'" in readme
