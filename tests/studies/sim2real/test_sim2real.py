"""The sim-to-real study's statistics, arms and report, on a result made here (the study
itself builds a set and trains: docs/sim2real.md has its measured run)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from spectrinsic.errors import StudyError
from spectrinsic.studies.registry import StudyOptions, get_study
from spectrinsic.studies.sim2real import (
    FACTORS,
    RunScore,
    Sim2RealResult,
    Sim2RealSettings,
    arms,
    dataset_config,
    factor_rows,
    format_sim2real,
    paired_difference,
    preset,
    t_interval,
    write_sim2real,
)
from spectrinsic.studies.sim2real.compute import _selection


def test_t_interval_matches_the_t_table():
    # t_{0.975, 4} = 2.7764 (Student's t table); values 1..5: mean 3, s = sqrt(2.5)
    iv = t_interval([1.0, 2.0, 3.0, 4.0, 5.0])
    assert iv.mean == 3.0
    assert iv.hi - iv.mean == pytest.approx(2.7764 * math.sqrt(2.5) / math.sqrt(5), rel=1e-4)
    assert iv.significant and not t_interval([-1.0, 1.0, 0.5]).significant
    assert math.isnan(t_interval([1.0]).lo)


def test_paired_difference_removes_the_seed_effect():
    # a seed effect far larger than the constant difference: paired, the difference is exact
    a, b = [10.0, 20.0, 30.0], [9.0, 19.0, 29.0]
    iv = paired_difference(a, b)
    assert (iv.mean, iv.lo, iv.hi) == (1.0, 1.0, 1.0) and iv.significant
    unpaired = (t_interval(a), t_interval(b))  # unpaired, the seeds' spread hides it
    assert unpaired[0].lo < unpaired[1].hi
    with pytest.raises(ValueError):
        paired_difference([1.0], [1.0, 2.0])


def test_arms_pair_up_by_factor_and_differ_in_one_thing():
    plan = {a.name: a for a in arms("Nikon 5100 (NPL)")}
    for with_, without in FACTORS.values():
        assert with_ in plan and without in plan
    assert plan["spectral"].layers.image == "image" and plan["rgb3"].layers.image == "image_rgb3"
    assert plan["spectral"].layers.reflectance == plan["rgb3"].layers.reflectance
    assert plan["camera"].layers.shading == "shading_sensor/Nikon 5100 (NPL)"
    assert (plan["coloured"].layers, plan["white"].layers) == (plan["spectral"].layers,) * 2


def test_white_and_coloured_arms_get_as_many_samples():
    folders = [Path(f"s{i}__v0__{fam}") for i, fam in
               enumerate(["white", "one-colour", "two-colour", "white", "two-colour"])]  # fmt: skip
    plan = {a.name: a for a in arms("cam")}
    white, coloured = _selection(folders, plan["white"]), _selection(folders, plan["coloured"])
    assert len(white) == len(coloured) == 2 and not set(white) & set(coloured)
    assert all(w.endswith("__white") for w in white)
    assert len(_selection(folders, plan["spectral"])) == 5
    with pytest.raises(StudyError, match="white"):
        _selection(folders[1:3], plan["white"])


def test_presets_and_the_generator_settings():
    assert preset("small").seeds == (0, 1, 2)
    with pytest.raises(StudyError, match="smal"):
        preset("smal")
    with pytest.raises(StudyError, match="3"):
        Sim2RealSettings("x", seeds=(0, 1))
    config = dataset_config(preset("small"))
    assert {"spectral", "rgb3", "bands31"} <= set(config.render.modes)
    assert config.camera == "nikon-d5100-npl" and json.loads(config.source)["count"] == 48
    study = get_study("sim2real")
    assert study.settings(StudyOptions(preset="large", seed=5)).count == 400
    assert study.settings(StudyOptions(seed=5)).seed == 5


def _result() -> Sim2RealResult:
    runs = []
    for arm, base in (("spectral", 0.03), ("rgb3", 0.04), ("coloured", 0.03), ("white", 0.031),
                      ("camera", 0.05)):  # fmt: skip
        for seed in (0, 1, 2):
            runs.append(RunScore(arm, seed, base + 0.002 * seed, base / 2, 4, 1.0))
    runs[9] = RunScore("white", 0, 0.036, 0.015, 4, 1.0)  # spread: coloured vs white unclear
    samples = {r.arm: ["a", "b", "c", "d"] for r in runs}
    return Sim2RealResult(preset("small"), {"preset": "x"}, "abc", samples, runs,
                          {"image-as-reflectance": (0.045, 0.02)}, 10, 3, 60.0)  # fmt: skip


def test_report_says_which_differences_are_significant(tmp_path):
    result = _result()
    rows = {r["factor"]: r for r in factor_rows(result)}
    assert rows["spectral image"]["mit_diff"] == pytest.approx(-0.01)
    assert rows["spectral image"]["mit_significant"]
    assert not rows["coloured lights"]["mit_significant"]
    text = format_sim2real(result)
    assert "| spectral image | spectral / rgb3 |" in text and "not significant" in text
    paths = write_sim2real(result, tmp_path)
    assert paths["png"].stat().st_size > 0
    record = json.loads(paths["json"].read_text())
    assert record["config_hash"] == "abc" and len(record["runs"]) == 15


def test_preset_is_refused_for_another_study(tmp_path, capsys):
    from spectrinsic.cli import main

    out = tmp_path / "out"
    assert main(["study", "photometric", "--preset", "small", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "sim2real only" in err and not out.exists()
