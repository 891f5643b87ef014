"""Datasets from generated scenes and from the user's scene files (YAML, .blend, OBJ): every
ground-truth layer, `check` passes, splits by scene."""

import hashlib
import json
from pathlib import Path

import pytest

from spectrinsic.errors import SpectrinsicError
from spectrinsic.gt_export import check_dataset
from spectrinsic.pipeline.dataset import build_dataset
from spectrinsic.pipeline.presets import DatasetConfig
from spectrinsic.pipeline.source_plan import files_source, generator_source
from spectrinsic.scenes import load_scene
from tests.scenes._builders import build_blend

TINY = DatasetConfig.from_settings(
    "tiny-test",
    width=8,
    height=8,
    spp=2,
    max_depth=3,
    modes=("spectral", "rgb3"),
    per_light=True,
    seed=4,
)
#: Layers every sample carries at this config (a library sample's, from gt_export).
LAYERS = {
    "image",
    "reflectance",
    "shading",
    "residual",
    "illuminant",
    "light_share",
    "depth",
    "normals",
    "material_id",
    "object_id",
    "mask",
    "shading_grey",
    "shading_ratio",
}


def _files(root: Path, sample: str) -> dict[str, str]:
    return {
        p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted((root / sample).rglob("*"))
        if p.is_file() and p.name != "meta.json"
    }


def _layers(root: Path, sample: str) -> set[str]:
    return set(json.loads((root / sample / "meta.json").read_text())["layers"])


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    out = tmp_path_factory.mktemp("gen") / "set"
    cfg = TINY.with_options(source=generator_source("objects-on-ground", 20))
    report = build_dataset(out, cfg)
    assert report.ok, report.failed
    return out, report


@pytest.mark.slow
def test_twenty_generated_samples_pass_check_with_distinct_scenes(generated):
    out, report = generated
    assert len(report.built) == 20
    assert check_dataset(out) == []
    metas = [json.loads((out / o.sample_id / "meta.json").read_text()) for o in report.built]
    assert len({m["scene_hash"] for m in metas}) == 20
    assert all(LAYERS <= set(m["layers"]) for m in metas)


@pytest.mark.slow  # the shared 20-sample build takes ~100 s
def test_generated_scene_files_load_back_to_the_rendered_scene(generated):
    out, report = generated
    sample = report.built[0].sample_id
    scene = load_scene(out / "scenes" / f"{sample}.yaml")
    from spectrinsic.scenes import scene_hash

    assert scene_hash(scene) == json.loads((out / sample / "meta.json").read_text())["scene_hash"]


@pytest.mark.slow  # the shared 20-sample build takes ~100 s
def test_same_seed_rebuild_gives_identical_samples_and_scene_files(generated, tmp_path):
    out, report = generated
    again = tmp_path / "again"
    cfg = TINY.with_options(source=generator_source("objects-on-ground", 2))
    assert build_dataset(again, cfg).ok
    for o in sorted(p.name for p in again.iterdir() if "__v" in p.name):
        assert _files(again, o) == {k: v for k, v in _files(out, o).items()}
        name = f"scenes/{o}.yaml"
        assert (again / name).read_bytes() == (out / name).read_bytes()


@pytest.mark.slow  # the shared 20-sample build takes ~100 s
def test_splits_share_no_scene(generated):
    out, _ = generated
    manifest = json.loads((out / "manifest.json").read_text())
    scenes = {
        split: {manifest["samples"][s]["scene"] for s in ids}
        for split, ids in manifest["splits"].items()
    }
    assert sum(len(ids) for ids in manifest["splits"].values()) == manifest["n_samples"]
    assert not (scenes["train"] & scenes["val"]) and not (scenes["train"] & scenes["test"])
    assert not (scenes["val"] & scenes["test"]) and len(scenes["train"]) > len(scenes["test"])


@pytest.mark.slow
def test_views_of_one_scene_land_in_one_split(tmp_path):
    cfg = TINY.with_options(source=generator_source("rooms", 2, views=2))
    out = tmp_path / "rooms"
    assert build_dataset(out, cfg).ok and check_dataset(out) == []
    manifest = json.loads((out / "manifest.json").read_text())
    where = {s: split for split, ids in manifest["splits"].items() for s in ids}
    for scene in ("rooms-00000", "rooms-00001"):
        assert len({split for s, split in where.items() if s.startswith(scene)}) == 1


def _build_files(tmp_path, paths, **kw):
    out = tmp_path / "own"
    report = build_dataset(out, TINY.with_options(source=files_source(paths, **kw)))
    assert report.ok, report.failed
    assert check_dataset(out) == []
    return out, [o.sample_id for o in report.built]


def test_yaml_scene_gets_every_layer(tmp_path, repo_root):
    from spectrinsic.scenes import build, save_scene

    path = save_scene(
        build("obj-apple", seed=0, width=8, height=8), tmp_path / "mine" / "apple.yaml"
    )
    out, ids = _build_files(tmp_path, [path])
    # the id is the scene's own name (obj-apple), not the file's (apple.yaml)
    assert ids == ["obj-apple__v0__file"] and LAYERS <= _layers(out, ids[0])


def test_obj_with_material_map_gets_every_layer(tmp_path):
    obj = tmp_path / "pyramid.obj"
    (tmp_path / "pyramid.mtl").write_text("newmtl red\nKd 1 0 0\nnewmtl base\nKd 1 1 1\n")
    obj.write_text(
        "mtllib pyramid.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\n"
        "usemtl red\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nusemtl base\nf 1 4 3\nf 1 3 2\n"
    )
    out, ids = _build_files(
        tmp_path, [obj], materials={"red": "munsell:5R 4/14", "base": "flat:0.5"}
    )
    meta = json.loads((out / ids[0] / "meta.json").read_text())
    assert LAYERS <= set(meta["layers"])
    assert set(meta["materials"].values()) == {"munsell:5R 4/14", "flat:0.5"}


def test_obj_material_missing_from_the_map_is_a_one_line_error(tmp_path):
    from spectrinsic.scenes.sources import FileSource

    obj = tmp_path / "tri.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(SpectrinsicError, match="not in the material map") as info:
        FileSource(str(obj), 8, 8).build()
    assert "\n" not in str(info.value) and "tri.obj" in str(info.value)


def test_blend_scene_gets_every_layer(tmp_path):
    marker = tmp_path / "autorun.txt"
    blend = build_blend("make_blend.py", tmp_path / "test.blend", str(marker), "1", "0")
    out, ids = _build_files(tmp_path, [blend], materials={"Paint": "munsell:5PB 4/10"})
    assert LAYERS <= _layers(out, ids[0]) and not marker.exists()


def test_cli_generator_typo_is_a_one_line_error(tmp_path, capsys):
    from spectrinsic.cli import main

    rc = main(["dataset", "--out", str(tmp_path / "x"), "--generator", "room", "--count", "1"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "did you mean 'rooms'" in err and len(err.splitlines()) == 1


def test_render_ground_truth_is_the_dataset_path(tmp_path):
    from spectrinsic.cli import main
    from spectrinsic.scenes import build, save_scene

    path = save_scene(build("obj-cup", seed=0, width=8, height=8), tmp_path / "mine" / "cup.yaml")
    out = tmp_path / "gt"
    rc = main(
        [
            "-q",
            "render",
            str(path),
            "--ground-truth",
            "--out",
            str(out),
            "--width",
            "8",
            "--height",
            "8",
            "--spp",
            "2",
        ]
    )
    assert rc == 0 and check_dataset(out) == []
    assert LAYERS <= _layers(out, "obj-cup__v0__file")


def test_a_folder_given_to_scenes_is_named_a_folder_with_what_the_option_takes(tmp_path):
    """Not "no such file": the folder exists, and ``--scenes`` takes scene files."""
    (tmp_path / "d").mkdir()
    with pytest.raises(SpectrinsicError) as info:
        files_source([tmp_path / "d"])
    message = str(info.value)
    assert "is a folder; expected scene files" in message and "no such file" not in message
    assert message.endswith(str(tmp_path / "d" / "*.yaml"))
    with pytest.raises(SpectrinsicError, match="no such file"):
        files_source([tmp_path / "gone.yaml"])
