"""Evaluation of glossy samples (issue 21, item 3): the full or diffuse target and a predicted
``specular`` layer, on a rendered glossy room exported and loaded like any dataset sample."""

from __future__ import annotations

import csv
from dataclasses import replace

import numpy as np
import pytest

from spectrinsic.decompose.evaluation.evaluate import evaluate
from spectrinsic.decompose.evaluation.predictions import Predictions, write_predictions
from spectrinsic.decompose.evaluation.sample_fields import input_image
from spectrinsic.decompose.evaluation.targets import target_image, target_note
from spectrinsic.decompose.metrics import get_metric
from spectrinsic.decompose.report import write_report
from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import export_sample, load_sample, write_manifest
from spectrinsic.render import RenderSettings, render_batches
from spectrinsic.scenes.model import Material

SID = "room-gloss__v1__white"
#: Relative error of float32 layer storage (each layer rounded once).
FLOAT32_RTOL = 1e-5


@pytest.fixture(scope="module")
def dataset(make_room, tmp_path_factory):
    """A 24 × 24 room with a silver mirror wall and a glossy coated floor, exported and loaded."""
    scene = make_room(size=24)
    mats = list(scene.materials)
    mats[3] = Material("mirror", "flat:0", kind="conductor", metal="Ag")
    mats[4] = Material("floor", "munsell:5Y 8/2", kind="plastic", ior=1.5)
    scene = replace(scene, materials=tuple(mats))
    settings = RenderSettings(
        8, batches=2, modes=("bands31", "rgb3"), per_light=True, share_mode="rgb3"
    )
    result = render_batches(scene, settings, seed=5)
    root = tmp_path_factory.mktemp("glossy")
    config = {"preset": "test", "width": 24, "height": 24, "spp": 8, "seed": 5}
    export_sample(root, scene, result, sample_id=SID, config=config, seed=5)
    write_manifest(root, config)
    return root, load_sample(root / SID, space="srgb")  # evaluate scores the sRGB view


def _scores(out) -> dict[tuple[str, str, str], float]:
    with open(out / "scores.csv", newline="", encoding="utf-8") as f:
        rows = [r for r in csv.DictReader(f) if r["scenario"] == "srgb"]
    return {(r["method"], r["layer"], r["metric"]): float(r["value"]) for r in rows}


def _run(sample, out, preds: dict[str, Predictions], target: str) -> dict:
    run = evaluate([sample], out, methods=preds, cameras=False, figures=False, target=target)
    write_report(out, run)
    return _scores(out)


def test_the_diffuse_image_is_reflectance_times_shading_plus_residual(dataset):
    """The diffuse target is ``image − specular = reflectance ∘ shading + residual`` (the
    sample's own identity, in sRGB and per camera), and it differs from the full image where the
    floor and mirror shine."""
    _, s = dataset
    image = input_image(s)[1]
    diffuse = target_image(s, image, "diffuse")
    rebuilt = np.asarray(s["reflectance"], np.float64) * s["shading"] + s["residual"]
    tol = FLOAT32_RTOL * np.abs(image).max()
    np.testing.assert_allclose(diffuse, rebuilt, rtol=FLOAT32_RTOL, atol=tol)
    assert np.abs(image - diffuse).max() > 0.1 * np.abs(image).max()
    cam = next(k.split("/", 1)[1] for k in s if k.startswith("specular_camera/"))
    image_cam = input_image(s, cam)[1]
    rebuilt_cam = (
        np.asarray(s[f"reflectance_camera/{cam}"], np.float64) * s[f"shading_camera/{cam}"]
        + s[f"residual_camera/{cam}"]
    )
    np.testing.assert_allclose(
        target_image(s, image_cam, "diffuse", cam),
        rebuilt_cam,
        rtol=FLOAT32_RTOL,
        atol=FLOAT32_RTOL * np.abs(image_cam).max(),
    )
    assert target_image(s, image, "full") is image
    with pytest.raises(DatasetError, match="evaluation target"):
        target_image(s, image, "specular")


def test_perfect_prediction_scores_zero_on_the_diffuse_target(dataset, tmp_path):
    """Ground-truth reflectance, shading and specular: every error is 0 on the diffuse target
    (``shading_grey`` is left out: its truth is the luminance Y, the estimate's grey a channel
    mean, so it is not 0 even for a perfect shading)."""
    _, s = dataset
    write_predictions(
        tmp_path / "p",
        SID,
        reflectance=s["reflectance"],
        shading=s["shading"],
        specular=s["specular"],
    )
    scores = _run(s, tmp_path / "out", {"gt": Predictions(tmp_path / "p", name="gt")}, "diffuse")
    layers = {k[1] for k in scores}
    assert {"reflectance", "shading", "shading_grey", "specular"} <= layers
    for (_, layer, metric), value in scores.items():
        if layer != "shading_grey" and metric not in ("corr", "lcorr"):  # corr: 1 when perfect
            # 1e-5: an angle (degrees) of float32 round-off through arccos; errors are ≫ that
            assert value == pytest.approx(0.0, abs=1e-5), (layer, metric)


def _expected_shading_error(s, image: np.ndarray) -> float:
    """si-MSE of ``image / reflectance`` against ``shading``, computed here from the layers."""
    refl = np.asarray(s["reflectance"], np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        derived = np.where(refl > 0, np.clip(image, 0, None) / np.where(refl > 0, refl, 1), 0)
    return get_metric("si_mse").func(s["shading"], derived.astype(np.float32), mask=s["mask"])


def test_the_targets_differ_where_there_is_specular(dataset, tmp_path):
    """Ground-truth reflectance alone: the shading derived from the diffuse image (``image −
    specular``) and from the full image score as computed here from the layers, and differ;
    predicting the specular on the full target gives exactly the diffuse target's score."""
    _, s = dataset
    image = input_image(s)[1]
    write_predictions(tmp_path / "r", SID, reflectance=s["reflectance"])
    write_predictions(tmp_path / "rs", SID, reflectance=s["reflectance"], specular=s["specular"])
    preds = {n: Predictions(tmp_path / n, name=n) for n in ("r", "rs")}
    diffuse = _run(s, tmp_path / "d", preds, "diffuse")
    full = _run(s, tmp_path / "f", preds, "full")
    key = ("r", "shading", "si_mse")
    want_d = _expected_shading_error(s, image - s["specular"])
    want_f = _expected_shading_error(s, image)
    assert diffuse[key] == pytest.approx(want_d, rel=1e-6)
    assert full[key] == pytest.approx(want_f, rel=1e-6)
    # the metal's pixels weigh on both alike (their shading is defined, reflectance = 0 gives
    # no derived shading there), so the two differ by less than the specular alone would make
    assert abs(full[key] - diffuse[key]) > 0.05 * diffuse[key]
    assert full[("rs", "shading", "si_mse")] == pytest.approx(diffuse[key], rel=1e-6)
    assert diffuse[("r", "reflectance", "si_mse")] == full[("r", "reflectance", "si_mse")] == 0


def test_a_predicted_specular_is_scored_against_the_ground_truth(dataset, tmp_path):
    """A perfect specular scores 0, a wrong one (mirrored image) > 0, none gives no row."""
    _, s = dataset
    good, bad = tmp_path / "good", tmp_path / "bad"
    write_predictions(good, SID, reflectance=s["reflectance"], specular=s["specular"])
    write_predictions(bad, SID, reflectance=s["reflectance"], specular=s["specular"][::-1])
    write_predictions(tmp_path / "none", SID, reflectance=s["reflectance"])
    preds = {n: Predictions(tmp_path / n, name=n) for n in ("good", "bad", "none")}
    scores = _run(s, tmp_path / "out", preds, "full")
    for metric in ("si_mse", "lmse"):
        assert scores[("good", "specular", metric)] == pytest.approx(0.0, abs=1e-12)
        assert scores[("bad", "specular", metric)] > 1e-3
    assert not any(k[0] == "none" and k[1] == "specular" for k in scores)


def test_the_report_and_tables_name_the_target(dataset, tmp_path):
    """Glossy samples: every table says which target; matte samples on the default target get
    no such line (their outputs are as before)."""
    _, s = dataset
    write_predictions(tmp_path / "p", SID, reflectance=s["reflectance"])
    _run(s, tmp_path / "out", {"gt": Predictions(tmp_path / "p", name="gt")}, "diffuse")
    for name in (
        "REPORT.md",
        "lmse_by_condition.md",
        "colour_by_condition.md",
        "lmse_by_scenario.md",
        "table_3_2_objects.md",
    ):
        text = (tmp_path / "out" / name).read_text(encoding="utf-8")
        assert "Target: diffuse" in text.splitlines()[2], name
    assert target_note("full", glossy=False) == ""
    assert "Target: full" in target_note("full", glossy=True)


def test_cli_target(dataset, tmp_path, capsys):
    """``--target diffuse`` reaches the report; an unknown target is refused (rc 2)."""
    from spectrinsic.cli import main

    root, s = dataset
    write_predictions(tmp_path / "p", SID, reflectance=s["reflectance"])
    base = [
        "--quiet",
        "evaluate",
        "--dataset",
        str(root),
        "--no-cameras",
        "--no-figures",
        "--predictions",
        f"gt={tmp_path / 'p'}",
    ]
    assert main([*base, "--out", str(tmp_path / "out"), "--target", "diffuse"]) == 0
    assert "Target: diffuse" in (tmp_path / "out" / "REPORT.md").read_text(encoding="utf-8")
    with pytest.raises(SystemExit) as exc:
        main([*base, "--out", str(tmp_path / "o2"), "--target", "shiny"])
    assert exc.value.code == 2
    assert "--target" in capsys.readouterr().err
