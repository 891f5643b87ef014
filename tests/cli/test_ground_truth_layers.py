"""Issue 47: ``render --ground-truth`` takes every layer option ``dataset`` takes, through one
shared option group, and builds the same files as ``dataset --scenes`` of the same scene."""

from __future__ import annotations

import json

import pytest

from spectrinsic.cli import build_parser, main
from spectrinsic.cli.dataset_layers import LAYER_OPTIONS
from spectrinsic.gt_export.dataset.build_time import reproducible_bytes
from spectrinsic.scenes import build, save_scene

LAYERS = ["--camera", "nikon-5100-npl", "--spectral-layers", "--working-space", "rec2020"]


def _options(verb: str) -> set[str]:
    """The option strings of *verb*'s parser."""
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    return {o for a in sub.choices[verb]._actions for o in a.option_strings}


def test_both_verbs_take_the_shared_layer_options():
    for verb in ("dataset", "render"):
        assert set(LAYER_OPTIONS) <= _options(verb), verb


def test_render_ground_truth_equals_dataset_scenes_byte_for_byte(tmp_path):
    scene = save_scene(build("obj-cup", seed=0, width=12, height=8), tmp_path / "s" / "cup.yaml")
    a, b = tmp_path / "a" / "set", tmp_path / "b" / "set"  # same folder name: the gallery's title
    common = ["--spp", "2", *LAYERS, "--out"]
    assert main(["-q", "render", str(scene), "--ground-truth", *common, str(a)]) == 0
    assert main(["-q", "dataset", "--scenes", str(scene), *common, str(b)]) == 0
    files_a = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    files_b = sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file())
    assert files_a == files_b
    names = {p.name for p in files_a}
    assert {"spectral.exr", "sensor-nikon-5100-npl.exr"} <= names  # the layers were asked for
    different = [p for p in files_a if reproducible_bytes(a / p) != reproducible_bytes(b / p)]
    assert different == []
    # the gallery's camera-chain panel: the sensor layers in the order light goes through them
    (entry,) = json.loads((a / "gallery.json").read_text())["samples"]
    panel = [name.split("/")[0] for name, _ in entry["sensor"]["layers"]]
    assert panel[:3] == ["raw_sensor", "image_sensor_noisy", "processed_sensor"]
    assert (
        entry["sensor"]["camera"] == "nikon-5100-npl" and entry["sensor"]["electrons_per_unit"] > 0
    )


@pytest.mark.parametrize("option", [["--camera", "nikon-d3"], ["--spectral-layers"]])
def test_a_plain_render_refuses_layer_options(tmp_path, capsys, option):
    out = tmp_path / "o"
    assert main(["render", "obj-apple", *option, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{option[0]} applies only with --ground-truth" in err
    assert "Traceback" not in err and not out.exists()
