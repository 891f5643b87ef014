"""Issue 36, causes 7-10 and 14: inputs refused in one line (rc 2, no traceback) before any work.

Each case runs the command line in-process and checks the exit status, that stderr is one line
naming the input, and that ``--out`` was not created. None of them renders.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from spectrinsic.cli import main
from spectrinsic.gt_export.folders.build_folder import write_marker
from spectrinsic.pipeline.presets import get_preset
from tests.conftest import QUAD_YAML, TINY_BUILD, one_line_error

APPLE = "obj-apple__v0__white"
GENERATED = ["--generator", "objects-on-ground", "--count", "1", *TINY_BUILD]


def _scene(tmp_path: Path, text: str = QUAD_YAML) -> str:
    path = tmp_path / "scene.yaml"
    path.write_text(text)
    return str(path)


# -- cause 10: non-finite numbers in the records -------------------------------------------


@pytest.mark.parametrize(
    ("option", "value"), [("--light-saturation", "0,inf"), ("--chroma-range", "1,1e400")]
)
def test_a_range_with_an_infinite_end_is_refused(tmp_path, capsys, option, value):
    out = tmp_path / "ds"
    assert main(["dataset", *GENERATED, option, value, "--out", str(out)]) == 2
    one_line_error(capsys, option, "finite")
    assert not out.exists()


def test_the_json_spectrinsic_writes_is_strict():
    """A NaN or an infinity is not JSON (a browser's JSON.parse rejects ``Infinity``)."""
    from spectrinsic.gt_export.sample import canonical_json

    assert canonical_json({"a": 1.5}) == '{\n  "a": 1.5\n}\n'
    for bad in (math.nan, math.inf):
        with pytest.raises(ValueError, match="not JSON compliant"):
            canonical_json({"a": bad})


# -- cause 8: tracebacks instead of one line --------------------------------------------------


def test_a_yaml_file_with_a_control_character_isone_line_error(tmp_path, capsys):
    scene = _scene(tmp_path, QUAD_YAML.replace("name: quad", "name: qu\x01ad"))
    assert main(["render", scene, "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, "scene.yaml", "invalid YAML", "#x0001")


def test_a_face_index_beyond_32_bits_isone_line_error(tmp_path, capsys):
    scene = _scene(tmp_path, QUAD_YAML.replace("[0, 2, 3]", f"[0, 2, {2**70}]"))
    assert main(["render", scene, "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, "meshes[0].faces[1][2]", "32-bit")


def test_a_vertex_too_large_for_a_float_isone_line_error(tmp_path, capsys):
    scene = _scene(tmp_path, QUAD_YAML.replace("[-2, -2, 0]", f"[-2, -2, {10**400}]", 1))
    assert main(["render", scene, "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, "meshes[0].vertices", "too large")


def test_a_path_depth_beyond_mitsubas_integers_isone_line_error(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["render", _scene(tmp_path), "--out", str(out), "--max-depth", "2147483648"]) == 2
    one_line_error(capsys, "--max-depth 2147483648", "expected 1 to")
    assert not out.exists()


def _nested_meta(root: Path) -> Path:
    sample = root / APPLE
    sample.mkdir(parents=True)
    (sample / "meta.json").write_text("[" * 100_000 + "]" * 100_000)
    return sample


def test_check_of_a_deeply_nested_meta_json_is_one_line_per_problem(tmp_path, capsys):
    _nested_meta(tmp_path / "ds")
    assert main(["check", str(tmp_path / "ds")]) != 0
    out = capsys.readouterr()
    assert "Traceback" not in out.err + out.out and "RecursionError" not in out.err
    assert "not valid JSON" in out.err + out.out


def test_a_dataset_rerun_over_a_deeply_nested_meta_json_isone_line_error(tmp_path, capsys):
    root = tmp_path / "ds"
    write_marker(root, get_preset("preview").with_options(width=16, height=16, spp=2).config_hash())
    _nested_meta(root)
    assert main(["dataset", "--out", str(root), *TINY_BUILD, "--only", APPLE]) == 2
    one_line_error(capsys, APPLE)


# -- cause 7: options and keys that do not apply ------------------------------------------


@pytest.mark.parametrize(
    ("light", "key"),
    [
        ('{kind: point, spectrum: "cie:D65", power: 4, position: [0, 0, 2], direction: [0, 0, -1]}', "direction"),
        ('{kind: directional, spectrum: "cie:D65", power: 4, direction: [0, 0, -1], position: [0, 0, 2]}', "position"),
        ('{kind: point, spectrum: "cie:D65", power: 4, position: [0, 0, 2], size: [1, 1]}', "size"),
    ],
)  # fmt: skip
def test_a_light_key_of_another_kind_is_refused(tmp_path, capsys, light, key):
    text = QUAD_YAML.replace(
        '{kind: point, spectrum: "cie:D65", power: 4, position: [0, 0, 2]}', light
    )
    assert main(["render", _scene(tmp_path, text), "--out", str(tmp_path / "o")]) == 2
    one_line_error(capsys, f"lights[0].{key}", "light has no")


def test_save_scene_writes_only_the_keys_a_light_kind_uses(tmp_path):
    """A directional light carrying an (unused) position round-trips through a scene file."""
    import dataclasses

    from spectrinsic.scenes import load_scene, save_scene

    scene = load_scene(_scene(tmp_path))
    sun = dataclasses.replace(
        scene.lights[0], kind="directional", direction=(0.0, 0.0, -1.0), position=(5.0, 5.0, 5.0)
    )
    saved = save_scene(dataclasses.replace(scene, lights=(sun,)), tmp_path / "saved.yaml")
    assert "position" not in saved.read_text().split("lights:")[1].split("camera:")[0]
    assert load_scene(saved).lights[0].direction == (0.0, 0.0, -1.0)


@pytest.mark.parametrize(
    ("extra", "option"),
    [(["--condition", "white"], "--condition"), (["--view", "0"], "--view")],
)
def test_library_options_on_a_scene_file_are_refused(tmp_path, capsys, extra, option):
    out = tmp_path / "o"
    assert main(["render", _scene(tmp_path), "--out", str(out), *extra]) == 2
    one_line_error(capsys, option, "library scenes", "scene.yaml")
    assert not out.exists()


def test_file_options_on_a_library_scene_are_refused(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["render", "obj-apple", "--out", str(out), "--default-spectrum", "flat:0.5"]) == 2
    one_line_error(capsys, "--default-spectrum", "obj-apple")
    assert not out.exists()


@pytest.mark.parametrize(
    "extra",
    [["--glossy", "0.5"], ["--count", "3"], ["--texture-fraction", "0"], ["--sfu"]],
    ids=lambda e: e[0],
)
def test_generator_options_on_a_library_dataset_are_refused(tmp_path, capsys, extra):
    out = tmp_path / "ds"
    assert main(["dataset", *TINY_BUILD, "--only", APPLE, *extra, "--out", str(out)]) == 2
    one_line_error(capsys, extra[0], "applies to --generator")
    assert not out.exists()


def test_a_scene_file_option_on_a_generated_dataset_is_refused(tmp_path, capsys):
    out = tmp_path / "ds"
    args = ["dataset", *GENERATED, "--default-spectrum", "flat:0.5", "--out", str(out)]
    assert main(args) == 2
    one_line_error(capsys, "--default-spectrum", "applies to --scenes")
    assert not out.exists()


@pytest.mark.parametrize("spec", ["=DIR", "name="])
def test_predictions_without_a_name_or_folder_are_refused(spec):
    import argparse

    from spectrinsic.cli.evaluate import _methods
    from spectrinsic.errors import DatasetError

    args = argparse.Namespace(methods=None, predictions=[spec], png_encoding="linear")
    with pytest.raises(DatasetError, match="expected NAME=DIR"):
        _methods(args)


def test_an_empty_layer_list_is_refused(tmp_path, capsys):
    root = tmp_path / "ds"
    root.mkdir()
    (root / "manifest.json").write_text("{}")
    out = tmp_path / "shards"
    assert main(["export", str(root), "--out", str(out), "--layers", ""]) == 2
    one_line_error(capsys, "--layers ''")
    assert not out.exists()


# -- cause 9: bounds from the plan; cause 14: integrator x materials ------------------------


def test_a_billion_relit_variants_are_refused_before_work(tmp_path, capsys):
    out = tmp_path / "ds"
    args = ["dataset", "--scenes", _scene(tmp_path), *TINY_BUILD, "--store-transport"]
    assert main([*args, "--relight", "1000000000", "--out", str(out)]) == 2
    one_line_error(capsys, "--relight 1000000000", "at most 1000")
    assert not out.exists()


def test_gloss_with_the_passes_integrator_is_refused_before_the_first_sample(tmp_path, capsys):
    out = tmp_path / "ds"
    args = ["dataset", "--generator", "rooms", "--glossy", "0.5", "--integrator", "passes"]
    assert main([*args, "--count", "1", *TINY_BUILD, "--out", str(out)]) == 2
    one_line_error(capsys, "--glossy/--metallic", "passes")
    assert not out.exists()
