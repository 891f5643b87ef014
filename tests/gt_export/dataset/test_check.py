"""``check_dataset`` and ``spectrinsic check``: a sound set passes, damage is found."""

from __future__ import annotations

import json

import numpy as np
import pytest

from spectrinsic.gt_export import check_dataset, export_sample, write_manifest
from spectrinsic.gt_export.formats.exr import read_exr, read_exr_attributes, write_exr


@pytest.fixture
def built(tmp_path, one_light_sample, two_light_sample, config):
    for sid, (scene, result) in (("one", one_light_sample), ("two", two_light_sample)):
        export_sample(tmp_path, scene, result, sample_id=sid, config=config, seed=1)
    write_manifest(tmp_path, config)
    return tmp_path


def _rewrite(path, layer, change):
    """Rewrite one layer of an EXR file (keeping channel names), as a buggy writer would."""
    order = json.loads(read_exr_attributes(path)["spectrinsic.channels"])
    arrays = read_exr(path)
    arrays[layer] = change(arrays[layer].copy())
    write_exr(path, arrays, channel_names=order)


def test_a_sound_dataset_passes(built):
    assert check_dataset(built) == []


def test_a_corrupted_file_is_found(built):
    path = built / "two" / "intrinsics.exr"
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    problems = check_dataset(built)
    assert any(p.startswith("two: ") and "intrinsics.exr" in p and "SHA-256" in p for p in problems)
    assert not any(p.startswith("one: ") for p in problems)


def test_nan_and_negative_values_are_found(built):
    def add_nan(a):
        a[2, 3, 1] = np.nan
        return a

    def negative(a):
        a[0, 0] = -1.0
        return a

    _rewrite(built / "one" / "intrinsics.exr", "shading", add_nan)
    _rewrite(built / "two" / "geometry.exr", "depth", negative)
    problems = check_dataset(built)
    assert any(p.startswith("one: ") and "'shading'" in p and "1 NaN" in p for p in problems)
    assert any(p.startswith("two: ") and "'depth'" in p and "negative" in p for p in problems)


def test_a_broken_identity_is_found(built):
    def scale(a):
        return a * 1.001

    _rewrite(built / "one" / "intrinsics.exr", "shading", scale)
    problems = check_dataset(built)
    assert any(p.startswith("one: image:") and "reflectance * shading" in p for p in problems)


def test_missing_files_samples_and_manifest_are_found(built):
    import shutil

    (built / "one" / "previews" / "depth.png").unlink()
    shutil.rmtree(built / "two")
    problems = check_dataset(built)
    assert any(p.startswith("one: ") and "depth.png" in p and "missing" in p for p in problems)
    assert any(p.startswith("two: ") and "manifest.json" in p for p in problems)
    (built / "manifest.json").unlink()
    assert "<dataset>: manifest.json is missing" in check_dataset(built)


def test_cli_exit_status_and_report(built, capsys):
    from spectrinsic.cli import main

    assert main(["-q", "check", str(built)]) == 0
    assert "ok: 2 samples" in capsys.readouterr().out
    (built / "one" / "scene.json").write_text("{}")
    assert main(["-q", "check", str(built)]) == 1
    out = capsys.readouterr().out
    assert (
        "one: 2 problem(s)" in out
        and "SHA-256 in meta.json" in out
        and "SHA-256 in manifest.json" in out
    )


def test_noise_from_two_batches_is_reported_and_flagged(tmp_path, synth, config):
    """Batches at ±10 % of the cube: the relative standard error of their mean is exactly 0.1
    (sqrt(Σ(±0.1x)² / (2·1)) / x), for image and shading alike."""
    import dataclasses

    from spectrinsic.gt_export.dataset.check import noise_report
    from spectrinsic.gt_export.dataset.manifest import noise_summary
    from spectrinsic.gt_export.sample.meta import read_meta

    scene = synth.make_scene(("planck:2800K",))
    result = synth.make_result(scene)
    cube = result.raw["bands31"]
    result = dataclasses.replace(
        result, batch_raw=({"bands31": cube * 1.1}, {"bands31": cube * 0.9})
    )
    folder = export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=1)
    write_manifest(tmp_path, config)
    meta = json.loads((folder / "meta.json").read_text())
    for layer in ("image", "shading_raw"):
        assert meta["noise"][layer]["median"] == pytest.approx(0.1, rel=1e-6)
    assert meta["noise"]["batches"] == 2
    manifest = json.loads((tmp_path / "manifest.json").read_text())
    assert manifest["noise"] == noise_summary([read_meta(folder)])
    lines, flagged = noise_report(tmp_path, threshold=0.05)
    assert flagged == ["s"] and "shading_raw median 10.0 %" in lines[0]
    assert noise_report(tmp_path, threshold=0.2)[1] == []
