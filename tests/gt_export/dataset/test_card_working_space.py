"""Issue 47: the card, the manifest and the evaluation's REPORT describe the set's own working
space: an ACEScg set names its white and never says "clipped" (it clips nothing); scores.csv
and scored.json name each sample's lighting group and the dataset's config hash."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from spectrinsic.cli import main
from spectrinsic.gt_export.dataset.card_text import colour_conventions, percent
from spectrinsic.gt_export.layers.spectral_intrinsics import residual_summary
from spectrinsic.scenes import build, save_scene
from spectrinsic.spectra.working_space import working_space

ACESCG_WHITE = "(0.978, 1.003, 1.079)"


@pytest.fixture(scope="module")
def acescg_set(tmp_path_factory):
    """A one-sample ACEScg set (the default working space) and its evaluation."""
    root = tmp_path_factory.mktemp("acescg")
    scene = save_scene(build("obj-cup", seed=0, width=12, height=8), root / "s" / "cup.yaml")
    data, ev = root / "set", root / "ev"
    tiny = ["--preset", "preview", "--spp", "2"]
    assert main(["-q", "dataset", "--scenes", str(scene), *tiny, "--out", str(data)]) == 0
    args = ["--methods", "image-as-shading", "--no-figures", "--no-estimates", "--no-cameras"]
    assert main(["-q", "evaluate", "--dataset", str(data), "--out", str(ev), *args]) == 0
    return data, ev


def test_an_acescg_set_names_its_white_and_never_says_clipped(acescg_set):
    data, ev = acescg_set
    card = (data / "DATASET.md").read_text(encoding="utf-8")
    manifest_text = (data / "manifest.json").read_text(encoding="utf-8")
    report = (ev / "REPORT.md").read_text(encoding="utf-8")
    white = working_space("acescg").white
    assert f"{white[0]:.3f}, {white[1]:.3f}, {white[2]:.3f}" == ACESCG_WHITE.strip("()")
    for name, text in (("card", card), ("manifest", manifest_text), ("REPORT", report)):
        assert "clipped" not in text.lower(), name
    assert (
        "Working space: ACEScg" in card and f"perfect white is `white_d65` = {ACESCG_WHITE}" in card
    )
    assert "perfect white is (1, 1, 1)" not in card and "e+0" not in card
    assert f"ACEScg, perfect white under D65 = {ACESCG_WHITE}" in report
    manifest = json.loads(manifest_text)
    space = manifest["working_space"]["acescg"]
    np.testing.assert_allclose(space["white_d65"], white, atol=1e-6)
    assert space["shading"] == "negative channels kept" and space["samples"] == 1
    assert "out_of_gamut_share" in manifest["residual_share"]["all"]


def test_scores_and_scored_json_name_the_lighting_group_and_config_hash(acescg_set):
    data, ev = acescg_set
    chash = json.loads((data / "manifest.json").read_text())["config_hash"]
    with (ev / "scores.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert rows and {(r["lighting"], r["config_hash"]) for r in rows} == {("WL", chash)}
    scored = json.loads((ev / "scored.json").read_text())
    assert scored["lighting"] == {"obj-cup__v0__file": "WL"}
    assert scored["config_hash"] == chash


def test_evaluate_on_a_sample_folder_names_its_datasets_preset(acescg_set, tmp_path):
    data, _ = acescg_set
    args = ["--methods", "image-as-shading", "--no-figures", "--no-estimates", "--no-cameras"]
    out = tmp_path / "one"
    assert (
        main(
            [
                "-q",
                "evaluate",
                "--dataset",
                str(data / "obj-cup__v0__file"),
                "--out",
                str(out),
                *args,
            ]
        )
        == 0
    )
    assert json.loads((out / "scored.json").read_text())["preset"] == "preview"


def test_an_srgb_set_says_its_shading_is_clipped_and_old_records_read():
    srgb = colour_conventions([working_space("srgb")])
    assert "clipped into the residual" in srgb["shading_sign"]
    assert "(1.000, 1.000, 1.000)" in srgb["white"]
    meta = {"lights": [{"spectrum": "cie:D65"}], "residual_share": {"image": 0.01}}
    old = residual_summary([meta | {"shading_clipping": {"pixels": 0.5}}])["all"]
    assert old["clipped_pixels"]["median"] == 0.5  # a sample without a working space: sRGB
    new = meta | {
        "shading_clipping": {"pixels": 0.25},
        "working_space": {"name": "acescg", "shading_clipped": False},
    }
    assert residual_summary([new])["all"]["out_of_gamut_share"]["median"] == 0.25


def test_percentages_are_written_for_people():
    assert [percent(f) for f in (0.999, 1.0, 0.0237, 1.23e-4, 0.0)] == [
        "99.9 %",
        "100 %",
        "2.37 %",
        "0.0123 %",
        "0 %",
    ]


def test_load_dataset_takes_a_split_like_torch_dataset(acescg_set):
    from spectrinsic.errors import DatasetError
    from spectrinsic.gt_export import load_dataset

    data, _ = acescg_set
    loaded = [s["meta"]["sample_id"] for s in load_dataset(data, split="train", verify=False)]
    assert loaded == ["obj-cup__v0__file"]
    with pytest.raises(DatasetError, match="val"):  # a 1-scene set has no val scene
        list(load_dataset(data, split="val"))
