"""``spectrinsic study``: both spectral studies print their tables and write their files."""

from __future__ import annotations

import json

import pytest

from spectrinsic.cli import build_parser, main


def test_study_is_registered_with_three_studies():
    args = build_parser().parse_args(["study", "rendering", "--out", "x", "--seed", "3"])
    assert args.study == "rendering" and args.seed == 3
    args = build_parser().parse_args(["study", "photometric"])
    assert str(args.out) == "results"


@pytest.mark.slow
def test_reconstruction_error_cli_writes_table_and_extension(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("SPECTRINSIC_DATA", raising=False)
    assert main(["-q", "study", "reconstruction-error", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert (
        "23.84 [23.84 +0.00]" in out
    )  # 3 sensors, two bounces, max: thesis Table 5.2, and the difference
    assert "note: skipped sfu" in out
    for name in (
        "reconstruction_error.json",
        "reconstruction_error.csv",
        "reconstruction_error.png",
        "reconstruction_error_extended.json",
        "reconstruction_error_extended.csv",
        "reconstruction_error_delta_e.csv",
        "reconstruction_error_extended.png",
    ):
        assert (tmp_path / name).stat().st_size > 0, name
    doc = json.loads((tmp_path / "reconstruction_error.json").read_text())
    assert len(doc["rows"]) == 6
    assert {"n_sensors", "bounces", "mean_pct", "sd_pct", "max_pct"} <= set(doc["rows"][0])
    for key in (
        "wavelength_start",
        "wavelength_end",
        "wavelength_step",
        "sigma_fraction",
        "pair_threshold",
        "chip_threshold",
        "illuminant",
        "reflectances",
        "sensor_centres_nm",
    ):
        assert key in doc["settings"], key
    assert doc["settings"]["sensor_centres_nm"]["3"] == [450.0, 550.0, 650.0]


def test_photometric_cli_prints_table_and_writes_json(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("SPECTRINSIC_DATA", raising=False)
    assert main(["-q", "study", "photometric", "--out", str(tmp_path), "--seed", "7"]) == 0
    out = capsys.readouterr().out
    assert "SC1_vs_SC4" in out and "Nikon 5100 (NPL)" in out
    doc = json.loads((tmp_path / "photometric.json").read_text())
    assert doc["settings"]["seed"] == 7
    assert (tmp_path / "photometric.png").stat().st_size > 0
