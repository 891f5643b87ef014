"""Writing samples (atomic, reproducible), manifest, dataset card, and loading them back."""

from __future__ import annotations

import hashlib
import json
import sys

import numpy as np
import pytest

from spectrinsic.errors import DatasetError, MissingDependencyError
from spectrinsic.gt_export import (
    config_hash,
    export_sample,
    is_complete,
    load_dataset,
    load_sample,
    sample_dirs,
    torch_dataset,
)
from spectrinsic.gt_export.layers import LayerSettings

FLOAT32_RTOL = 4 * float(np.finfo(np.float32).eps)


def test_sample_round_trips_through_the_loader(tmp_path, two_light_sample, config):
    scene, result = two_light_sample
    folder = export_sample(
        tmp_path,
        scene,
        result,
        LayerSettings(cameras=("camera:Nikon 5100 (NPL)",), write_cube=True),
        sample_id="s",
        config=config,
        seed=5,
    )
    sample = load_sample(folder)
    for key in (
        "image",
        "reflectance",
        "shading",
        "illuminant",
        "mask",
        "depth",
        "normals",
        "ids",
        "meta",
        "image_camera/Nikon 5100 (NPL)",
        "cube",
        "image_rgb3",
    ):
        assert key in sample, key
    assert sample["image"].shape == (12, 16, 3) and sample["image"].dtype == np.float32
    assert sample["mask"].dtype == bool
    np.testing.assert_array_equal(sample["mask"], result.aovs["mask"])
    np.testing.assert_array_equal(sample["ids"]["material"], result.aovs["material_id"])
    np.testing.assert_array_equal(sample["depth"], result.aovs["depth"])
    # the cube is stored bit-exactly
    assert sample["cube"].tobytes() == result.raw["bands31"].tobytes()
    for key in ("residual", "shading_ratio", "shading_grey", "light_share"):
        assert key in sample, key
    rebuilt = sample["reflectance"].astype(np.float64) * sample["shading"] + sample["residual"]
    np.testing.assert_allclose(rebuilt, sample["image"], rtol=FLOAT32_RTOL, atol=1e-6)
    meta = sample["meta"]
    assert meta["materials"]["0"] == "munsell:5R 4/14"
    assert [light["spectrum"] for light in meta["lights"]] == ["planck:2800K", "cie:FL11"]
    assert len(meta["lights"][0]["spd"]) == 81
    assert meta["seed"] == 5 and meta["variants"] == ["synthetic"]
    assert meta["config_hash"] == config_hash(config)
    assert "timings" not in meta["render"]  # run-dependent: would break reproducible files
    for key, record in meta["layers"].items():
        assert record["units"], key
    assert set(meta["matrices"]["S_Sen"]) == {"Nikon 5100 (NPL)"}


def test_scene_json_is_the_scene_as_plain_data(tmp_path, one_light_sample, config):
    import dataclasses

    from spectrinsic.scenes.model import scene_hash, scene_to_dict

    scene, result = one_light_sample
    scene = dataclasses.replace(
        scene, metadata={"kind": "test", "seed": np.int64(4), "views": (1, 2)}
    )
    folder = export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=5)
    data = json.loads((folder / "scene.json").read_text(encoding="utf-8"))
    assert data == scene_to_dict(scene)
    # the file reproduces scene_hash: the canonical JSON of everything but the metadata
    del data["metadata"]
    blob = json.dumps(data, sort_keys=True, separators=(",", ":")).encode()
    assert (
        hashlib.sha256(blob).hexdigest()
        == scene_hash(scene)
        == json.loads((folder / "meta.json").read_text(encoding="utf-8"))["scene_hash"]
    )


def test_is_complete_follows_the_config_hash(tmp_path, one_light_sample, config):
    scene, result = one_light_sample
    folder = export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=1)
    assert is_complete(folder, config_hash(config))
    assert not is_complete(folder, config_hash({**config, "spp": 2}))
    (folder / "intrinsics.exr").unlink()
    assert not is_complete(folder, config_hash(config))
    assert not is_complete(tmp_path / "absent", config_hash(config))


def test_a_write_failing_midway_leaves_nothing_complete_looking(
    tmp_path, one_light_sample, config, monkeypatch
):
    from spectrinsic.gt_export.formats import png

    scene, result = one_light_sample
    calls = {"n": 0}
    real = png.write_png

    def failing(path, rgb8):
        calls["n"] += 1
        if calls["n"] == 3:
            raise OSError("disk full (simulated)")
        return real(path, rgb8)

    monkeypatch.setattr(png, "write_png", failing)
    with pytest.raises(OSError, match="simulated"):
        export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=1)
    # it really failed midway, after EXR files and two previews (later previews may have been
    # under way in the write threads, gt_export.sample.write_pool)
    assert calls["n"] >= 3
    assert not (tmp_path / "s").exists()
    assert list(tmp_path.iterdir()) == []  # the temporary folder is gone too
    assert sample_dirs(tmp_path) == []


def test_a_rewrite_replaces_an_old_sample_whole(tmp_path, one_light_sample, config):
    scene, result = one_light_sample
    folder = export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=1)
    old_meta = (folder / "meta.json").read_text()
    new_config = {**config, "spp": 4}
    export_sample(tmp_path, scene, result, sample_id="s", config=new_config, seed=1)
    assert (folder / "meta.json").read_text() != old_meta
    assert is_complete(folder, config_hash(new_config))
    assert [p.name for p in tmp_path.iterdir()] == ["s"]


def test_a_sample_folder_holding_a_users_file_is_never_replaced(tmp_path, one_light_sample, config):
    scene, result = one_light_sample
    folder = export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=1)
    (folder / "notes.txt").write_text("mine")
    with pytest.raises(DatasetError, match="notes.txt"):
        export_sample(tmp_path, scene, result, sample_id="s", config={**config, "spp": 4}, seed=1)
    assert (folder / "notes.txt").read_text() == "mine"
    assert is_complete(folder, config_hash(config))  # the old sample is untouched
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s"]  # no temporary left


def test_a_folder_named_like_the_sample_but_not_spectrinsics_is_refused(
    tmp_path, one_light_sample, config
):
    scene, result = one_light_sample
    (tmp_path / "s").mkdir()
    (tmp_path / "s" / "thesis.tex").write_text("a")
    with pytest.raises(DatasetError, match="no valid spectrinsic meta.json"):
        export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=1)
    assert (tmp_path / "s" / "thesis.tex").read_text() == "a"
    assert [p.name for p in tmp_path.iterdir()] == ["s"]


def test_meta_json_records_the_sha256_of_every_listed_file(tmp_path, one_light_sample, config):
    scene, result = one_light_sample
    folder = export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=1)
    meta = json.loads((folder / "meta.json").read_text())
    assert set(meta["sha256"]) == set(meta["files"]) and "meta.json" not in meta["files"]
    for rel, digest in meta["sha256"].items():
        assert hashlib.sha256((folder / rel).read_bytes()).hexdigest() == digest
    # a file swapped for another (valid) file of the same kind is caught
    (folder / "geometry.exr").write_bytes((folder / "image.exr").read_bytes())
    assert not is_complete(folder, config_hash(config))


def test_same_inputs_give_identical_files(tmp_path, two_light_sample, config):
    scene, result = two_light_sample
    a = export_sample(tmp_path / "a", scene, result, sample_id="s", config=config, seed=3)
    b = export_sample(tmp_path / "b", scene, result, sample_id="s", config=config, seed=3)
    files_a = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    files_b = sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file())
    assert files_a == files_b
    for rel in files_a:
        assert (a / rel).read_bytes() == (b / rel).read_bytes(), rel


def test_manifest_hashes_every_file_and_records_provenance(built, config):

    manifest = json.loads((built / "manifest.json").read_text())
    assert manifest["n_samples"] == 2 and set(manifest["samples"]) == {"a-one", "b-two"}
    files = manifest["samples"]["a-one"]["files"]
    on_disk = {p.relative_to(built).as_posix() for p in (built / "a-one").rglob("*") if p.is_file()}
    assert set(files) == on_disk
    for rel, digest in files.items():
        assert hashlib.sha256((built / rel).read_bytes()).hexdigest() == digest
    assert manifest["config"] == config and manifest["seed"] == 7
    assert manifest["mitsuba_variants"] == ["synthetic"]
    assert "munsell:5R 4/14" in manifest["spectral_data"]["spectra_used"]
    assert manifest["versions"]["OpenEXR"] != "absent"


def test_dataset_card_describes_every_layer(built):
    import html

    card = (built / "DATASET.md").read_text()
    meta = json.loads((built / "b-two" / "meta.json").read_text())
    for key, record in meta["layers"].items():
        assert f"`{key}`" in card
        assert html.escape(record["units"], quote=False) in card  # "L<i>" is not an <i> tag
    assert "linear" in card and "D65" in card and "load_sample" in card


def test_load_dataset_iterates_complete_samples_in_order(built):
    (built / ".spectrinsic-tmp-c-x").mkdir()  # an interrupted write is not a sample
    ids = [s["meta"]["sample_id"] for s in load_dataset(built, layers=["image"])]
    assert ids == ["a-one", "b-two"]


def test_torch_adapter_without_torch_says_what_to_install(built, monkeypatch):
    monkeypatch.setitem(sys.modules, "torch", None)  # makes `import torch` fail
    with pytest.raises(MissingDependencyError, match="spectrinsic\\[torch\\]"):
        torch_dataset(built)


def test_meta_json_floats_carry_at_most_the_stated_digits(tmp_path, two_light_sample, config):
    """Fitted matrices and colours are rounded (issue 9, point 10), so BLAS's last bits never
    reach the file; the rounding keeps 12 significant digits, far above their accuracy."""
    from spectrinsic.gt_export.sample import META_DIGITS

    scene, result = two_light_sample
    folder = export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=3)
    floats: list[float] = []

    def walk(value):
        if isinstance(value, float):
            floats.append(value)
        elif isinstance(value, dict):
            for v in value.values():
                walk(v)
        elif isinstance(value, list):
            for v in value:
                walk(v)

    meta = json.loads((folder / "meta.json").read_text())
    walk(meta["matrices"])
    assert len(floats) > 50
    assert all(float(f"{x:.{META_DIGITS}g}") == x for x in floats)
    assert any(float(f"{x:.{META_DIGITS - 2}g}") != x for x in floats)  # not rounded coarser


def test_previews_of_one_kind_share_an_exposure_and_state_their_encoding(
    tmp_path, two_light_sample, config
):
    """Every image mode uses the exposure of ``image`` (so brightness differences are real), and
    the stated scale turns a PNG pixel back into the EXR value within 8-bit precision."""
    import colour
    import matplotlib.image

    scene, result = two_light_sample
    folder = export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=3)
    layers = json.loads((folder / "meta.json").read_text())["layers"]
    scales = {k: r["preview_encoding"]["scale"] for k, r in layers.items() if k.startswith("image")}
    assert len(scales) >= 2 and len(set(scales.values())) == 1
    assert layers["error_rgb3"]["preview_encoding"] == {
        "kind": "colormap",
        "cmap": "magma",
        "vmin": 0.0,
        "vmax": 0.1,
    }
    png_rgb = matplotlib.image.imread(folder / layers["image_rgb3"]["preview"])[..., :3]
    linear = colour.cctf_decoding(png_rgb.astype(float), function="sRGB") / scales["image_rgb3"]
    exr = load_sample(folder, space="srgb")["image_rgb3"]  # previews show the sRGB view
    unclipped = (png_rgb < 0.98).all(axis=-1) & (png_rgb > 0.1).all(axis=-1)
    assert unclipped.sum() > 20
    rel = np.abs(linear[unclipped] - exr[unclipped]) / np.abs(exr[unclipped])
    assert rel.max() < 0.03  # one 8-bit step of sRGB at mid-grey is about 1 %


def test_light_records_carry_only_the_fields_of_their_kind(tmp_path, two_light_sample, config):
    scene, result = two_light_sample  # point lights: a position, no direction, size or cone
    folder = export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=3)
    for light in json.loads((folder / "meta.json").read_text())["lights"]:
        assert light["kind"] == "point" and len(light["position"]) == 3
        assert not {"direction", "size", "cutoff_deg"} & set(light)


def test_dataset_card_shows_the_diversity_figure(built):
    from spectrinsic.gt_export.dataset.diversity import diversity_figure, diversity_stats
    from spectrinsic.gt_export.sample import sample_dirs
    from spectrinsic.gt_export.sample.meta import read_meta

    card = (built / "DATASET.md").read_text()
    assert "diversity.png" in card and (built / "diversity.png").is_file()
    spread = next(
        line for line in card.splitlines() if line.startswith("Colour spread: lights cover")
    )
    assert "nan" not in spread and "Duv" in spread
    samples = sample_dirs(built)
    stats = diversity_stats(samples, [read_meta(s) for s in samples])
    n_lights = sum(len(read_meta(s).lights) for s in samples)
    assert len(stats["luminance_decades"]) == len(samples) and len(stats["light_cct"]) == n_lights
    assert all(1000 < t < 25000 for t in stats["light_cct"])
    assert len(stats["samples"]) == len(samples) and len(stats["material_chroma"]) >= len(samples)
    assert len(diversity_figure(stats).axes) == 8
