"""Issue 19: a scene file keeps its camera size unless --resolution is given (and the CLI says
which applies); `render` and `render --ground-truth` share their defaults; re-rendering a scene
a generated build saved reproduces its sample (same id, same seed) unless --new-sample."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from spectrinsic.cli import build_parser, main
from spectrinsic.gt_export import load_sample
from spectrinsic.gt_export.formats.exr import read_exr
from spectrinsic.pipeline.presets import get_preset
from spectrinsic.scenes import build, save_scene
from spectrinsic.scenes.sample_id import SampleId

TINY = ["--spp", "2", "--max-depth", "3"]


@pytest.fixture()
def wide_cup(tmp_path):
    """A YAML scene whose camera is 12 x 8 pixels (no preset has that size)."""
    return save_scene(build("obj-cup", seed=0, width=12, height=8), tmp_path / "mine" / "cup.yaml")


def test_render_keeps_the_files_camera_size_unless_resolution_is_given(wide_cup, tmp_path, capsys):
    assert (
        main(
            [
                "render",
                str(wide_cup),
                "--modes",
                "rgb3",
                "--no-aovs",
                *TINY,
                "--out",
                str(tmp_path / "own"),
            ]
        )
        == 0
    )
    assert "12x8 (the scene file's camera)" in capsys.readouterr().err
    assert read_exr(tmp_path / "own" / "rgb3.exr")["xyz"].shape == (8, 12, 3)
    assert (
        main(
            [
                "render",
                str(wide_cup),
                "--modes",
                "rgb3",
                "--no-aovs",
                *TINY,
                "--resolution",
                "6x4",
                "--out",
                str(tmp_path / "asked"),
            ]
        )
        == 0
    )
    assert "6x4 (--resolution 6x4)" in capsys.readouterr().err
    assert read_exr(tmp_path / "asked" / "rgb3.exr")["xyz"].shape == (4, 6, 3)


def test_ground_truth_keeps_the_files_camera_size_and_says_so(wide_cup, tmp_path, capsys):
    out = tmp_path / "gt"
    assert (
        main(
            [
                "render",
                str(wide_cup),
                "--ground-truth",
                "--preset",
                "preview",
                "--spp",
                "2",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    assert "cup.yaml: the file's camera size" in capsys.readouterr().err
    assert load_sample(out / "obj-cup__v0__file")["image"].shape == (8, 12, 3)


def test_render_and_ground_truth_share_their_defaults():
    parser = build_parser()
    plain = parser.parse_args(["render", "obj-apple", "--out", "x"])
    gt = parser.parse_args(["render", "obj-apple", "--out", "x", "--ground-truth"])
    # not given, they are None on the parser (so that one given where it does not apply is
    # refused) and resolve to the default preset's: the plain render's depth, the GT preset
    from spectrinsic.cli.render import _render_settings

    assert gt.preset is None and plain.max_depth is None
    preset = get_preset("default")
    default = get_preset("default")
    assert _render_settings(plain, ["rgb3"]).max_depth == preset.render.max_depth
    assert (preset.width, preset.height, preset.render.spp) == (
        default.width,
        default.height,
        default.render.spp,
    )


def test_a_saved_generated_scene_reproduces_its_sample(tmp_path, capsys):
    tiny = ["--preset", "preview", "--resolution", "12x12", "--spp", "2", "--workers", "1"]
    gen = tmp_path / "gen"
    assert (
        main(
            [
                "-q",
                "dataset",
                *tiny,
                "--generator",
                "objects-on-ground",
                "--count",
                "1",
                "--out",
                str(gen),
            ]
        )
        == 0
    )
    (saved,) = sorted((gen / "scenes").glob("*.yaml"))
    sid = saved.stem
    original = load_sample(gen / sid)
    again = tmp_path / "again"
    capsys.readouterr()
    assert main(["dataset", *tiny[:-2], "--scenes", str(saved), "--out", str(again)]) == 0
    seed = original["meta"]["seed"]
    assert f"reproduces its saved sample {sid} with seed {seed}" in capsys.readouterr().err
    copy = load_sample(again / sid)  # same id, same seed: the same sample
    assert copy["meta"]["seed"] == seed
    assert np.array_equal(copy["image"], original["image"])
    assert np.array_equal(copy["reflectance"], original["reflectance"])

    new = tmp_path / "new"
    assert (
        main(
            ["-q", "dataset", *tiny[:-2], "--scenes", str(saved), "--new-sample", "--out", str(new)]
        )
        == 0
    )
    (folder,) = [p for p in new.iterdir() if p.is_dir() and "__v0__file" in p.name]
    assert (
        folder.name == f"{SampleId.parse(sid).scene}__v0__file"  # the scene's own name
        and json.loads((folder / "meta.json").read_text())["seed"] != seed
    )


def test_a_saved_sample_record_that_escapes_is_refused(tmp_path, capsys):
    scene = build("obj-cup", seed=0, width=12, height=8)
    scene = dataclasses.replace(scene, metadata={"sample": {"id": "../../x__v0__y", "seed": 1}})
    bad = save_scene(scene, tmp_path / "bad.yaml")
    assert main(["render", str(bad), "--ground-truth", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "metadata.sample" in err[0]


def test_render_writes_an_srgb_png_beside_each_exr(wide_cup, tmp_path):
    """The PNG is the EXR's XYZ through colour-science's XYZ -> sRGB (IEC 61966-2-1), exposed so
    the 99th percentile of positive luminance is 1: computed here independently."""
    colour = pytest.importorskip("colour")
    from PIL import Image

    out = tmp_path / "png"
    assert (
        main(
            [
                "-q",
                "render",
                str(wide_cup),
                "--modes",
                "rgb3,spectral",
                "--no-aovs",
                *TINY,
                "--out",
                str(out),
            ]
        )
        == 0
    )
    for mode in ("rgb3", "spectral"):
        xyz = read_exr(out / f"{mode}.exr")["xyz"].astype(np.float64)
        linear = colour.XYZ_to_RGB(xyz, colour.RGB_COLOURSPACES["sRGB"], apply_cctf_encoding=False)
        y = linear @ np.array([0.2126, 0.7152, 0.0722])
        scale = 1.0 / np.percentile(y[np.isfinite(y) & (y > 0)], 99.0)
        want = np.round(255 * colour.cctf_encoding(np.clip(linear * scale, 0, 1), "sRGB"))
        got = np.asarray(Image.open(out / f"{mode}.png"))
        assert got.shape == (8, 12, 3) and got.dtype == np.uint8
        assert np.abs(got.astype(int) - want).max() <= 1, mode
        meta = json.loads((out / "meta.json").read_text())
        assert meta["previews"][mode]["exposure"] == pytest.approx(scale, rel=1e-6)
