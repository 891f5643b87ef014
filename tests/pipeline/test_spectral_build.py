"""``dataset --spectral-layers`` (issue 30): the opt-in setting, its refusal without the cube, a
real one-sample build that ``check`` passes, the manifest's summary and
``check --max-residual-share``. 12 x 12 pixels at 2 spp: bookkeeping, not physics (that is
``tests/gt_export/layers/test_spectral_layers.py``)."""

from __future__ import annotations

import json

import pytest

from spectrinsic.cli import main
from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import check_dataset, load_sample
from spectrinsic.pipeline.dataset import build_dataset
from spectrinsic.pipeline.presets import DatasetConfig, get_preset

TINY = DatasetConfig.from_settings(
    "tiny-test",
    width=12,
    height=12,
    spp=2,
    max_depth=3,
    batches=1,
    modes=("rgb3", "bands31"),
    cameras=(),
    seed=5,
    spectral_layers=True,
)
SAMPLE = "room-living__v0__two-colour-a"


def test_the_setting_is_opt_in_hashed_only_when_on_and_needs_the_cube():
    preset = get_preset("default")
    assert not preset.spectral_layers and "spectral_layers" not in preset.settings()
    assert preset.with_options(spectral_layers=True).config_hash() != preset.config_hash()
    with pytest.raises(DatasetError, match="need the 31-band cube"):
        get_preset("preview").with_options(spectral_layers=True)


def test_cli_refuses_spectral_layers_without_the_cube_in_one_line(tmp_path, capsys):
    rc = main(["dataset", "--preset", "preview", "--spectral-layers", "--out", str(tmp_path / "d")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "--spectral-layers" in err[0]
    assert not (tmp_path / "d").exists() or not any((tmp_path / "d").iterdir())


def test_a_build_with_spectral_layers_is_sound_and_reports_its_residual(tmp_path, capsys):
    out = tmp_path / "dataset"
    report = build_dataset(out, TINY, only=SAMPLE)
    assert report.ok, report.failed
    assert check_dataset(out) == []
    sample = load_sample(out / SAMPLE)
    assert sample["shading_bands"].shape == (12, 12, 31)
    shares = sample["meta"]["residual_share"]
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["samples"][SAMPLE]["residual_share"] == shares
    assert manifest["residual_share"]["all"]["samples"] == 1
    assert manifest["residual_share"]["all"]["rgb"]["median"] == pytest.approx(shares["image"])
    card = (out / "DATASET.md").read_text()
    assert "## Residual by light family" in card and "| all | 1 |" in card
    rgb = shares["image"]
    assert main(["check", str(out), "--max-residual-share", f"{rgb * 1.01}"]) == 0
    capsys.readouterr()
    assert main(["check", str(out), "--max-residual-share", f"{rgb * 0.99}"]) == 1
    assert "residual share" in capsys.readouterr().out
    assert main(["check", str(out), "--max-residual-share", "-1"]) == 2
