"""Issue 36, cause 9: the disk a build needs is estimated from its plan and compared with the
free space of ``--out`` before the first sample (the free space is faked here)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from spectrinsic.cli import main
from spectrinsic.pipeline import disk_space
from spectrinsic.pipeline.presets import get_preset
from tests.conftest import QUAD_YAML


def _free(monkeypatch, free: int) -> None:
    real = shutil.disk_usage

    def fake(path: str | os.PathLike[str]):
        total, used, _ = real(path)
        return shutil._ntuple_diskusage(total, used, free)  # type: ignore[attr-defined]

    monkeypatch.setattr(disk_space.shutil, "disk_usage", fake)


def _args(tmp_path: Path, out: Path) -> list[str]:
    scene = tmp_path / "scene.yaml"
    scene.write_text(QUAD_YAML)
    return ["dataset", "--scenes", str(scene), "--resolution", "32x32", "--out", str(out), "-q"]


def test_a_build_that_cannot_fit_is_refused_before_any_work(tmp_path, monkeypatch, capsys):
    _free(monkeypatch, 100_000)
    out = tmp_path / "new" / "ds"
    assert main(_args(tmp_path, out)) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "Traceback" not in err, err
    assert "needs about" in err and "100.0 kB is free" in err and "--ignore-disk-space" in err
    assert not (tmp_path / "new").exists()


def test_ignore_disk_space_goes_ahead_and_the_estimate_is_near_the_real_size(
    tmp_path, monkeypatch, capsys
):
    _free(monkeypatch, 100_000)
    out = tmp_path / "ds"
    assert main([*_args(tmp_path, out), "--ignore-disk-space"]) == 0
    actual = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
    config = get_preset("default").with_options(width=32, height=32)
    estimate = disk_space.estimate_build_bytes(config, 1)
    assert 0.5 * actual <= estimate <= 4 * actual, (estimate, actual)
    # a resumed build with nothing left to build needs no space
    capsys.readouterr()
    assert main(_args(tmp_path, out)) == 0


@pytest.mark.parametrize(
    "option, factor",
    [("store_transport", 1.5), ("spectral_layers", 1.5), ("relight", 2.0)],
)
def test_the_estimate_grows_with_what_the_plan_stores(option, factor):
    base = get_preset("default").with_options(width=256, height=256)
    value = 3 if option == "relight" else True
    more = base.with_options(
        **({option: value, "store_transport": True} if option == "relight" else {option: value})
    )
    assert disk_space.estimate_sample_bytes(more) > factor * disk_space.estimate_sample_bytes(base)
    preview = get_preset("preview").with_options(width=256, height=256)
    assert disk_space.estimate_sample_bytes(preview) < disk_space.estimate_sample_bytes(base)
