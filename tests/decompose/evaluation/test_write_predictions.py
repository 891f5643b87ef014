"""write_predictions: a method's arrays in the layout ``evaluate --predictions`` reads
(issue 19: no helper wrote 16-bit PNG or EXR predictions; Pillow cannot write 16-bit RGB)."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.decompose import Predictions, evaluate, write_predictions
from spectrinsic.decompose.evaluation.predictions import read_layer
from spectrinsic.decompose.evaluation.sample_fields import input_image
from spectrinsic.errors import DatasetError
from tests.decompose.evaluation.test_evaluate import _sample

#: Half a 16-bit code: the largest error of rounding a value in [0, 1] to code / 65535.
HALF_CODE = 0.5 / 65535
#: Largest slope of the sRGB decoding on [0, 1] (at 1: 2.4 / 1.055), which scales that error.
SRGB_SLOPE = 2.4 / 1.055


def _arrays(h=5, w=7, seed=0):
    rng = np.random.default_rng(seed)
    return (
        rng.uniform(0.0, 1.0, (h, w, 3)),
        rng.uniform(0.0, 6.0, (h, w, 3)),
        rng.uniform(0, 1, (h, w)),
    )


def test_exr_round_trip_is_float32_exact(tmp_path):
    refl, shad, _ = _arrays()
    out = write_predictions(tmp_path, "s__v0__white", reflectance=refl, shading=shad)
    assert out.folder == tmp_path / "s__v0__white" and set(out.files) == {"reflectance", "shading"}
    assert out.files["shading"].name == "shading.exr" and out.scales == {
        "reflectance": 1.0,
        "shading": 1.0,
    }
    for name, truth in (("reflectance", refl), ("shading", shad)):
        back = read_layer(out.folder, name, (5, 7), encoding="linear")
        np.testing.assert_array_equal(back, truth.astype(np.float32))


def test_png_round_trip_to_16_bit_quantisation(tmp_path):
    refl, shad, grey = _arrays()
    out = write_predictions(tmp_path, "s", reflectance=refl, shading=shad, fmt="png")
    assert out.files["reflectance"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    back = read_layer(out.folder, "reflectance", (5, 7), encoding="linear")
    assert np.abs(back - refl).max() <= HALF_CODE  # within [0, 1]: written unscaled
    scale = out.scales["shading"]
    assert scale == pytest.approx(shad.max())  # above 1: divided by its maximum
    back = read_layer(out.folder, "shading", (5, 7), encoding="linear")
    assert np.abs(back * scale - shad).max() <= HALF_CODE * scale
    write_predictions(tmp_path, "g", shading=grey, fmt="png", encoding="srgb")
    back = read_layer(tmp_path / "g", "shading", (5, 7), encoding="srgb")
    assert back.shape == (5, 7, 3)  # grey shading applies to all channels
    assert np.abs(back[..., 1] - grey).max() <= HALF_CODE * SRGB_SLOPE


def test_refusals_are_one_line_errors_and_keep_files(tmp_path):
    refl, shad, _ = _arrays()
    write_predictions(tmp_path, "s", reflectance=refl)
    before = (tmp_path / "s" / "reflectance.exr").read_bytes()
    with pytest.raises(DatasetError, match="exists; pass overwrite=True"):
        write_predictions(tmp_path, "s", reflectance=refl * 0.5)
    assert (tmp_path / "s" / "reflectance.exr").read_bytes() == before
    write_predictions(tmp_path, "s", reflectance=refl * 0.5, overwrite=True)
    assert (tmp_path / "s" / "reflectance.exr").read_bytes() != before
    with pytest.raises(DatasetError, match="reader prefers it"):
        write_predictions(tmp_path, "s", reflectance=refl, fmt="png", overwrite=True)
    for bad in ("../escape", "a/b", ".."):
        with pytest.raises(DatasetError, match="one folder name"):
            write_predictions(tmp_path, bad, reflectance=refl)
    with pytest.raises(DatasetError, match="give reflectance, shading or both"):
        write_predictions(tmp_path, "t")
    with pytest.raises(DatasetError, match=r"expected \(H, W, 3\)$"):
        write_predictions(tmp_path, "t", reflectance=refl[..., 0])
    with pytest.raises(DatasetError, match="NaN"):
        write_predictions(tmp_path, "t", shading=np.full((2, 2), np.nan))
    assert not (tmp_path / "t").exists() and not (tmp_path.parent / "escape").exists()


@pytest.mark.parametrize("fmt", ["exr", "png"])
def test_ground_truth_written_as_predictions_scores_perfectly(tmp_path, fmt):
    """End to end: the true layers, written by the helper, score LMSE 0 (to quantisation)."""
    samples = [
        _sample("obj-a__v0__white", 0, (1, 1, 1), False),
        _sample("room-b__v1__two-colour-a", 2, (0.7, 0.9, 1.0), False),
    ]
    for s in samples:
        write_predictions(
            tmp_path / "pred",
            s["meta"]["sample_id"],
            fmt=fmt,
            reflectance=s["reflectance"],
            shading=s["shading"],
        )
    result = evaluate(
        samples,
        tmp_path / "out",
        methods={"truth": Predictions(tmp_path / "pred")},
        seed=0,
        figures=False,
        save_estimates=False,
    )
    lmse = [s.value for s in result.scores if s.metric == "lmse" and s.scenario == "srgb"]
    assert len(lmse) >= 4  # reflectance and shading of both samples
    assert max(lmse) <= (1e-12 if fmt == "exr" else 1e-6)
    # a method that is not the truth scores visibly worse through the same files
    s = samples[0]
    write_predictions(
        tmp_path / "flat", s["meta"]["sample_id"], reflectance=np.ones_like(s["reflectance"])
    )
    worse = evaluate(
        samples[:1],
        tmp_path / "out2",
        methods={"flat": Predictions(tmp_path / "flat")},
        seed=0,
        figures=False,
        save_estimates=False,
    )
    assert max(x.value for x in worse.scores if x.metric == "lmse") > 1e-3
    assert input_image(s)[1].shape == s["reflectance"].shape


def test_a_sample_without_predictions_suggests_samples(tmp_path):
    refl, _, _ = _arrays()
    write_predictions(tmp_path, "done", reflectance=refl)
    with pytest.raises(DatasetError, match=r"no reflectance or shading .* pass --samples"):
        Predictions(tmp_path).load("not-done", "srgb", refl, np.ones(refl.shape[:2], bool))
