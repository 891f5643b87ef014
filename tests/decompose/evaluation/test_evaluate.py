"""Evaluation on synthetic samples shaped like the loader's dicts; tables, files and the CLI."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from spectrinsic.decompose.evaluation.evaluate import evaluate
from spectrinsic.decompose.report import write_report
from spectrinsic.decompose.synthetic import mondrian

METHODS = ["colour-retinex", "image-as-reflectance"]
CAMERA = "Test Cam (NPL)"
#: float32 EXR storage.
FLOAT32 = 1e-6


def _sample(sid: str, seed: int, light, with_camera: bool):
    scene = mondrian(48, 48, seed=seed, light=light)
    sample = {
        "image": scene.image.astype(np.float32),
        "reflectance": scene.reflectance.astype(np.float32),
        "shading": scene.shading.astype(np.float32),
        "mask": np.ones((48, 48), bool),
        "ids": {"material": scene.material_ids, "object": np.zeros((48, 48), np.int32)},
        "meta": {"sample_id": sid},
    }
    if with_camera:
        rng = np.random.default_rng(seed)
        light_m = np.diag([1.2, 1.0, 0.7]) + 0.02 * rng.standard_normal((3, 3))
        sensor = np.eye(3) + 0.05 * rng.standard_normal((3, 3))
        sample["image_camera/" + CAMERA] = scene.image @ (light_m @ sensor).T
        sample["meta"]["matrices"] = {
            "S_Sen": {CAMERA: sensor.tolist()},
            "L_CLig": {CAMERA: {"scene": light_m.tolist()}, "srgb": {"scene": light_m.tolist()}},
        }
    return sample


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    out = tmp_path_factory.mktemp("evaluation")
    samples = [
        _sample("obj-a__v0__white", 0, (1, 1, 1), True),
        _sample("obj-a__v0__one-colour", 1, (1.0, 0.8, 0.5), False),
        _sample("room-b__v1__two-colour-a", 2, (0.7, 0.9, 1.0), False),
    ]
    seen = []
    res = evaluate(samples, out, methods=METHODS, seed=3, progress=seen.append)
    write_report(out, res)  # as the CLI does
    return res, out, seen


def test_scores_csv_and_progress(result):
    res, out, seen = result
    assert seen == ["obj-a__v0__white", "obj-a__v0__one-colour", "room-b__v1__two-colour-a"]
    rows = list(csv.DictReader((out / "scores.csv").open()))
    assert set(rows[0]) == {"sample", "method", "scenario", "layer", "metric", "value"} | {
        "lighting",  # issue 47: the sample's lighting group and its dataset's config hash
        "config_hash",
    }
    groups = {r["sample"]: r["lighting"] for r in rows}
    assert groups == {
        "obj-a__v0__white": "WL",
        "obj-a__v0__one-colour": "1L",
        "room-b__v1__two-colour-a": "2L",
    }
    assert {r["metric"] for r in rows if r["layer"] == "reflectance"} >= {"lmse", "whdr", "dssim"}
    assert {r["scenario"] for r in rows} == {
        "srgb",
        "SC1_test-cam-npl",
        "SC3b_test-cam-npl",
        "SC4_test-cam-npl",
    }
    assert len(rows) == len(res.scores)


def test_sc1_with_exact_matrices_equals_the_srgb_input(result):
    res, _, _ = result
    by = {(s.sample, s.method, s.scenario, s.layer, s.metric): s.value for s in res.scores}
    for method in METHODS:
        key = ("obj-a__v0__white", method)
        assert by[(*key, "SC1_test-cam-npl", "reflectance", "lmse")] == pytest.approx(
            by[(*key, "srgb", "reflectance", "lmse")], rel=1e-6
        )


def test_tables(result):
    _, out, _ = result
    cond = list(csv.DictReader((out / "lmse_by_condition.csv").open()))
    objects = {r["method"]: r for r in cond if r["scene_kind"] == "object"}
    complex_ = {r["method"]: r for r in cond if r["scene_kind"] == "complex"}
    assert set(objects) == set(METHODS) and set(complex_) == set(METHODS)
    assert objects["colour-retinex"]["reflectance_WL"] not in ("", "nan")
    assert complex_["colour-retinex"]["reflectance_2L"] not in ("", "nan")
    assert float(objects["colour-retinex"]["reflectance_WL"]) < float(
        objects["image-as-reflectance"]["reflectance_WL"]
    )
    md = (out / "lmse_by_condition.md").read_text()
    assert "Single objects" in md and "Complex scenes" in md
    scen = list(csv.DictReader((out / "lmse_by_scenario.csv").open()))
    assert {r["camera"] for r in scen} == {CAMERA}
    assert all(r[sc] not in ("", "nan") for r in scen for sc in ("SC1", "SC3b", "SC4"))


def test_estimates_and_figures_written(result):
    from spectrinsic.gt_export.formats.exr import read_exr

    _, out, _ = result
    folder = out / "estimates" / "colour-retinex" / "srgb" / "obj-a__v0__white"
    refl = read_exr(folder / "reflectance.exr")["reflectance"]
    shad = read_exr(folder / "shading.exr")["shading"]
    image = mondrian(48, 48, seed=0).image
    np.testing.assert_allclose(refl * shad, image, rtol=1e-5, atol=FLOAT32)
    assert (out / "figures" / "room-b__v1__two-colour-a.png").stat().st_size > 1000


def test_cli_without_dataset_says_how_to_build_it(tmp_path, capsys):
    from spectrinsic.cli import main

    status = main(["evaluate", "--dataset", str(tmp_path / "missing"), "--out", str(tmp_path)])
    assert status == 2
    assert "spectrinsic dataset" in capsys.readouterr().err


def test_single_objects_are_scored_on_their_own_mask_not_the_ground():
    from spectrinsic.decompose.evaluation.sample_fields import evaluation_mask

    sample = _sample("obj-a__v0__white", 0, (1, 1, 1), False)
    objects = np.zeros((48, 48), np.int32)
    objects[:, 24:] = 1  # right half is the ground
    sample["ids"]["object"] = objects
    sample["meta"]["objects"] = {"0": "cup", "1": "ground"}
    mask = evaluation_mask(sample)
    assert mask[:, :24].all() and not mask[:, 24:].any()

    room = dict(sample, meta={"sample_id": "room-b__v0__white", "objects": {"1": "ground"}})
    assert evaluation_mask(room).all()  # complex scenes keep every surface


def test_table_3_2_averages_grey_shading_and_grey_reflectance():
    from spectrinsic.decompose.evaluation.evaluate import Score
    from spectrinsic.decompose.report.tables import table_3_2

    samples = {
        "obj-a__v0__white": ("object", "white"),
        "obj-b__v0__one-colour": ("object", "one-colour"),
        "room__v0__white": ("complex", "white"),
    }
    scores = []
    for sid, refl, shad in (
        ("obj-a__v0__white", 0.2, 0.4),
        ("obj-b__v0__one-colour", 0.6, 0.0),
        ("room__v0__white", 9.0, 9.0),
    ):
        scores += [
            Score(sid, "m", "srgb", "reflectance_grey", "lmse", refl),
            Score(sid, "m", "srgb", "shading_grey", "lmse", shad),
            Score(sid, "m", "srgb", "reflectance", "lmse", 99.0),
        ]
    rows = {r["lighting"]: r for r in table_3_2(scores, samples)}
    assert rows["WL"]["lmse"] == pytest.approx(0.3)  # (0.2 + 0.4) / 2; the room is not an object
    assert rows["1L"]["lmse"] == pytest.approx(0.3)  # (0.6 + 0.0) / 2
    assert rows["all"]["lmse"] == pytest.approx(0.3)
    assert np.isnan(rows["2L"]["lmse"]) and np.isnan(rows["all"]["corr"])
