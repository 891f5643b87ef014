"""The one reader of ``meta.json``: damage is named (file and field) and never reaches a reader
as a KeyError; the seal catches what no schema can; reads verify and confine paths."""

from __future__ import annotations

import ast
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.errors import DatasetError, SampleMetaError
from spectrinsic.gt_export import export_sample, load_sample, read_meta, write_manifest
from spectrinsic.gt_export.sample import SEAL_KEY, meta_seal

PACKAGE = Path(__file__).resolve().parents[3]


@pytest.fixture
def two(tmp_path, one_light_sample, two_light_sample, config):
    """Two exported samples (batches of noise in one), with a manifest."""
    import dataclasses

    for sid, (scene, result) in (("a-one", one_light_sample), ("b-two", two_light_sample)):
        cube = result.raw["bands31"]
        result = dataclasses.replace(
            result, batch_raw=({"bands31": cube * 1.1}, {"bands31": cube * 0.9})
        )
        export_sample(tmp_path, scene, result, sample_id=sid, config=config, seed=3)
    write_manifest(tmp_path, config)
    return tmp_path


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert old in text, old
    path.write_text(text.replace(old, new, 1), encoding="utf-8")


def test_a_written_meta_json_is_valid_and_sealed(two):
    meta = read_meta(two / "b-two")
    assert meta.sealed is True and meta.sample_id == "b-two" and meta.size == (12, 16)
    assert meta.noise["shading_raw"].median == pytest.approx(0.1, rel=1e-6)
    raw = json.loads((two / "b-two" / "meta.json").read_text())
    assert raw[SEAL_KEY] == meta_seal(raw)
    assert {i.image for i in meta.identities} <= set(meta.layers)


#: (what the damage is, text to replace, replacement, the field the error must name)
DAMAGE = [
    ("bit-flipped key", '"median"', '"mediaN"', "noise.image.median: missing"),
    ("field of the wrong type", '"seed": 3', '"seed": "3"', "seed: expected a whole number"),
    ("non-finite number", '"share": 1.0', '"share": NaN', "non-finite number NaN"),
    ("missing field", '"scene": "synthetic",', "", "scene: missing"),
    ("unknown field", '"size":', '"colour": 3, "size":', "colour: not a field spectrinsic writes"),
    (
        "negative size",
        '"size": [\n    12',
        '"size": [\n    -12',
        "size[0]: expected a whole number >= 1",
    ),
    (
        "layer path outside",
        '"file": "image.exr"',
        '"file": "../../outside/secret.exr"',
        "layers.image.file: expected a path inside the sample folder",
    ),
]


@pytest.mark.parametrize("old, new, field", [d[1:] for d in DAMAGE], ids=[d[0] for d in DAMAGE])
def test_damaged_meta_json_raises_one_line_naming_file_and_field(two, old, new, field):
    path = two / "a-one" / "meta.json"
    _edit(path, old, new)
    for read in (
        lambda: read_meta(two / "a-one"),
        lambda: load_sample(two / "a-one", verify=False),
    ):
        with pytest.raises(SampleMetaError) as info:
            read()
        message = str(info.value)
        assert message.startswith(f"{path}: ") and field in message and "\n" not in message


def test_one_edited_digit_breaks_the_seal(two):
    path = two / "b-two" / "meta.json"
    text = path.read_text()
    start = text.index('"L_CLig"')
    digit = next(i for i in range(start, len(text)) if text[i] in "123456789")
    path.write_text(text[:digit] + str(int(text[digit]) % 9 + 1) + text[digit + 1 :])
    with pytest.raises(SampleMetaError, match=f"{SEAL_KEY}: the content does not match its seal"):
        read_meta(two / "b-two")
    assert read_meta(two / "b-two", verify=False).sealed is False
    from spectrinsic.gt_export import check_dataset

    problems = check_dataset(two)
    assert any(p.startswith("b-two: meta.json does not match its seal") for p in problems)


def test_load_sample_refuses_a_file_swapped_with_another_samples(two):
    shutil.copyfile(two / "b-two" / "image.exr", two / "a-one" / "image.exr")
    with pytest.raises(DatasetError, match=r"image\.exr: does not match its SHA-256 in meta\.json"):
        load_sample(two / "a-one")
    # trusting the files (verify=False) reads the other sample's pixels, as before
    np.testing.assert_array_equal(
        load_sample(two / "a-one", layers=["image"], verify=False)["image"],
        load_sample(two / "b-two", layers=["image"])["image"],
    )


def test_export_and_evaluate_refuse_a_swapped_file_in_one_line(two, tmp_path_factory, capsys):
    from spectrinsic.cli import main

    shutil.copyfile(two / "b-two" / "intrinsics.exr", two / "a-one" / "intrinsics.exr")
    out = tmp_path_factory.mktemp("verbs")
    pytest.importorskip("webdataset", reason="the shards extra (webdataset) is in the dev extra")
    for argv in (
        ["export", str(two), "--out", str(out / "shards")],
        [
            "evaluate",
            "--dataset",
            str(two),
            "--out",
            str(out / "eval"),
            "--methods",
            "image-as-reflectance",
        ],
    ):
        rc = main(["-q", *argv])
        err = capsys.readouterr().err.strip()
        assert rc == 2, (argv, err)
        assert len(err.splitlines()) == 1 and "Traceback" not in err
        assert "a-one/intrinsics.exr: does not match its SHA-256" in err


def _raw_meta_reads(tree: ast.AST) -> list[int]:
    """Lines that parse JSON (``json.load``/``json.loads``) in a function whose text mentions
    ``META_NAME`` or ``meta.json``: a ``meta.json`` parsed outside the sample module."""
    hits = []
    for node in ast.walk(tree):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        names = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
        texts = {
            n.value
            for n in ast.walk(node)
            if isinstance(n, ast.Constant) and isinstance(n.value, str)
        }
        about_meta = "META_NAME" in names or any("meta.json" in t for t in texts)
        for call in ast.walk(node):
            if (
                isinstance(call, ast.Call)
                and isinstance(call.func, ast.Attribute)
                and call.func.attr in ("load", "loads")
                and isinstance(call.func.value, ast.Name)
                and call.func.value.id == "json"
                and about_meta
            ):
                hits.append(call.lineno)
    return hits


def test_the_scanner_finds_a_raw_meta_json_read():
    code = "def f(p):\n    return json.loads((p / 'meta.json').read_text())\n"
    assert _raw_meta_reads(ast.parse(code)) == [2]
    assert _raw_meta_reads(ast.parse("def f(p):\n    return json.loads(p.read_text())\n")) == []


def test_no_module_outside_the_sample_module_parses_meta_json():
    """Only ``spectrinsic/gt_export/sample/meta.py`` (and the JSON reader it uses) parse ``meta.json``."""
    sample = PACKAGE / "spectrinsic" / "gt_export" / "sample"
    allowed = {sample / "meta.py", sample / "json_fields.py"}
    offenders = []
    for folder in ("spectrinsic",):
        for path in sorted((PACKAGE / folder).rglob("*.py")):
            if path in allowed:
                continue
            lines = _raw_meta_reads(ast.parse(path.read_text(encoding="utf-8")))
            offenders += [f"{path.relative_to(PACKAGE)}:{line}" for line in lines]
    assert offenders == []


def test_object_id_16777217_is_exported_and_loaded_exactly(tmp_path, synth, config):
    import dataclasses

    from spectrinsic.gt_export import check_dataset

    scene = synth.make_scene(("planck:2800K",))
    result = synth.make_result(scene)
    # the scene's mesh carries the id too: the semantic layer reads each object's class
    mesh = dataclasses.replace(scene.meshes[0], object_id=16777217)
    scene = dataclasses.replace(scene, meshes=(mesh,))
    big = np.where(result.aovs["object_id"] >= 0, 16777217, -1).astype(np.int32)
    result = dataclasses.replace(result, aovs={**result.aovs, "object_id": big})
    folder = export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=1)
    sample = load_sample(folder)
    assert sample["object_id"].dtype == np.int32
    np.testing.assert_array_equal(sample["object_id"], big)
    np.testing.assert_array_equal(sample["ids"]["object"], big)
    assert read_meta(folder).layers["object_id"].dtype == "int32"
    write_manifest(tmp_path, config)
    assert check_dataset(tmp_path) == []


def test_a_symbolic_link_out_of_the_sample_folder_is_not_inside(tmp_path):
    from spectrinsic.gt_export.sample import confined_path

    folder, outside = tmp_path / "s", tmp_path / "outside"
    (folder / "previews").mkdir(parents=True)
    outside.mkdir()
    (outside / "secret.exr").write_text("x")
    (folder / "image.exr").write_text("x")
    (folder / "previews" / "image.png").symlink_to(outside / "secret.exr")
    (folder / "linked").symlink_to(outside, target_is_directory=True)
    assert confined_path(folder, "image.exr") == folder / "image.exr"
    assert confined_path(folder, "previews/image.png") is None
    assert confined_path(folder, "linked/secret.exr") is None
    for bad in ("../outside/secret.exr", "/etc/passwd", "a\\b", ""):
        assert confined_path(folder, bad) is None
