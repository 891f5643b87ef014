"""Exact relighting from the per-light transport (issue 20, part 2), with real renders.

The independent reference is Mitsuba itself: the same scene rendered light by light with the
new spectra as emitter values (same seed, spp and depth), whose ground truth is computed by the
usual path. A relit sample must equal it to float rounding in every layer.
"""

from __future__ import annotations

import dataclasses
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import check_sample, export_sample, load_sample
from spectrinsic.gt_export.layers import LayerSettings
from spectrinsic.gt_export.relight import relight, relit_scene
from spectrinsic.gt_export.relight.augment import RandomRelight, relit_layers
from spectrinsic.gt_export.sample import META_NAME, SEAL_KEY, canonical_json, meta_seal, write_pool
from spectrinsic.gt_export.sample.render_spp import render_spp
from spectrinsic.gt_export.sample.transport_exr import TRANSPORT_NAME
from spectrinsic.render import RenderSettings, count_passes, render_batches
from spectrinsic.render.transport_render import render_transport_batches
from tests.gt_export._builders import render_transport_sample
from tests.gt_export.folders._holder import held_lock

#: Issue 20: a relit layer and the direct render's agree to float rounding, 1e-5 of the
#: layer's largest magnitude (float32 storage, and ē multiplied after the path sum, not inside).
RELIGHT_RTOL = 1e-5
#: The noise layers come from the batches' spread, stored as float16 deviations (issue 45's
#: compact transport): 11 significant bits, so they agree to 1e-3 of their largest value.
NOISE_RTOL = 1e-3
NEW_LIGHTS = {0: "cie:LED-RGB1", 1: "planck:3000K"}  # were planck:2800K, daylight:6500K
MODES = ("spectral", "rgb3", "rgb6", "bands31")
SEED = 11
#: Two batches of 2 samples per pixel each, the diagonal modes from the single traversal (the
#: default): the transport is the traversal's own split by light, and the direct render it is
#: compared with is another traversal with the new spectra (same seed, spp and depth).
SETTINGS = RenderSettings(spp=4, modes=MODES, batches=2, max_depth=4)
CONFIG = {"test": "relight"}


@pytest.fixture(scope="module")
def built(tmp_path_factory, make_room):
    """A two-light room sample stored with its transport (2 batches, denoised, two cameras)."""
    out = tmp_path_factory.mktemp("relight")
    scene = make_room(size=16)
    layers = LayerSettings(denoise=True)
    sample, _, _ = render_transport_sample(
        out, scene, SETTINGS, seed=SEED, sample_id="room__v0__two", config=CONFIG, layers=layers
    )
    return out, scene, sample


def _max_rel(a: np.ndarray, b: np.ndarray) -> float:
    scale = float(np.abs(b).max())
    return (
        float(np.abs(a.astype(np.float64) - b).max()) / scale
        if scale > 0
        else float(np.abs(a).max())
    )


def _tolerance(layer: str) -> float:
    """The agreement a relit *layer* keeps with a direct render (:data:`NOISE_RTOL` for the
    noise estimates, :data:`RELIGHT_RTOL` for everything else)."""
    return NOISE_RTOL if layer.startswith("noise_") else RELIGHT_RTOL


def _disagreeing(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> dict[str, float]:
    """The layers of *a* farther from *b*'s than their tolerance, with their errors."""
    errors = {k: _max_rel(a[k], b[k]) for k in a}
    return {k: e for k, e in errors.items() if e > _tolerance(k)}


def _arrays(sample: dict) -> dict[str, np.ndarray]:
    return {k: v for k, v in sample.items() if isinstance(v, np.ndarray)}


def _relit_and_direct(out, scene, sample, settings: RenderSettings, tag: str) -> tuple[dict, dict]:
    """The sample relit with :data:`NEW_LIGHTS`, and a direct render of the relit scene with
    *settings* (light by light), both loaded; every layer compared within the tolerance."""
    relit = relight(sample, NEW_LIGHTS, out / f"relit__v0__{tag}")
    assert check_sample(relit) == []
    new_scene = relit_scene(scene, NEW_LIGHTS)
    direct = render_batches(
        new_scene, settings.with_options(modes=MODES[1:], per_light=True), seed=SEED
    )
    reference = export_sample(
        out,
        new_scene,
        direct,
        LayerSettings(denoise=True),
        sample_id=f"direct__v0__{tag}",
        config=CONFIG,
        seed=SEED,
    )
    a, b = _arrays(load_sample(relit)), _arrays(load_sample(reference))
    assert set(a) == set(b)
    assert {
        "image",
        "shading",
        "residual",
        "illuminant",
        "light_share",
        "noise_image",
        "image_denoised",
        "shading_camera/Nikon 5100 (NPL)",
        "image_rgb6",
        "error_rgb3",
    } <= set(a)
    assert _disagreeing(a, b) == {}
    return a, {"relit": relit, "reference": reference}


def test_the_transport_comes_from_the_single_traversal_without_per_light_passes(make_room):
    """One traversal per batch carries every mode and light, plus the spectral pass: the
    transport costs the Mitsuba renders of a plain render (L x (1 + 2 + 11) + coverage
    passes per batch before), and its diagonal images are that render's to float rounding."""
    scene = make_room(size=8)
    settings = SETTINGS.with_options(spp=2, batches=1)
    calls: list[int] = []
    transport, result = render_transport_batches(scene, settings, seed=SEED, progress=calls.append)
    assert len(calls) == count_passes(scene, settings) == 2  # the traversal and the spectral pass
    assert "single" in transport.seconds and result.meta["integrator"] == "single"
    plain = render_batches(scene, settings, seed=SEED)
    for mode in MODES[1:]:
        np.testing.assert_allclose(
            result.raw[mode], plain.raw[mode], rtol=1e-5, atol=1e-7 * plain.raw[mode].max()
        )
    np.testing.assert_array_equal(result.images["spectral"], plain.images["spectral"])
    np.testing.assert_array_equal(result.aovs["coverage"], plain.aovs["coverage"])


def test_relit_sample_equals_a_direct_render_with_the_new_spectra(built):
    out, scene, sample = built
    a, paths = _relit_and_direct(out, scene, sample, SETTINGS, "two")
    relit, reference = paths["relit"], paths["reference"]
    # the new lights really changed the image (the comparison is not between equal samples)
    before = load_sample(sample, layers=["image", "illuminant"])
    assert _max_rel(a["image"], before["image"]) > 0.05
    meta_a = json.loads((relit / "meta.json").read_text())
    meta_b = json.loads((reference / "meta.json").read_text())
    assert [li["spectrum"] for li in meta_a["lights"]] == ["cie:LED-RGB1", "planck:3000K"]
    for la, lb in zip(meta_a["lights"], meta_b["lights"], strict=True):
        assert la["share"] == pytest.approx(lb["share"], rel=RELIGHT_RTOL)
        assert la["xy"] == pytest.approx(lb["xy"], rel=1e-12)
    assert meta_a["render"]["relit"]["from"] == "room__v0__two"
    assert meta_a["noise"]["batches"] == 2


def test_relit_sample_equals_a_direct_render_with_the_passes(tmp_path, make_room):
    """The transport from per-light passes (``integrator="passes"``, the scalar variants' way)
    relights as exactly, against a direct render with the same passes."""
    scene = make_room(size=12)
    settings = SETTINGS.with_options(integrator="passes", spp=2)
    sample, transport, result = render_transport_sample(
        tmp_path, scene, settings, seed=SEED, sample_id="room__v0__passes", config=CONFIG,
        layers=LayerSettings(denoise=True),
    )  # fmt: skip
    assert "single" not in transport.seconds and result.meta.get("integrator") != "single"
    _relit_and_direct(tmp_path, scene, sample, settings, "passes")


def test_relighting_with_the_own_spectra_gives_the_sample_back(built):
    out, scene, sample = built
    same = relight(
        sample, {i: li.spectrum for i, li in enumerate(scene.lights)}, out / "same__v0__two"
    )
    original, again = _arrays(load_sample(sample)), _arrays(load_sample(same))
    assert set(original) - set(again) == {"image_spectral"}  # not a band render: not relit
    # not bit for bit: the transport holds the batches' float32 mean and float16 deviations
    assert _disagreeing(again, original) == {}
    for key in ("reflectance", "material_id", "normals", "depth"):  # not relit: copied
        np.testing.assert_array_equal(again[key], original[key], err_msg=key)


def test_doubling_every_power_doubles_radiometric_layers_only(built):
    out, scene, sample = built
    own = {i: li.spectrum for i, li in enumerate(scene.lights)}
    twice = relit_layers(sample, own, powers={i: 2 * li.power for i, li in enumerate(scene.lights)})
    base = relit_layers(sample, own)
    for key in ("image", "shading_raw", "image_rgb6", "image_camera/Sigma SDMerill (NPL)"):
        np.testing.assert_allclose(
            twice[key], 2 * base[key], rtol=RELIGHT_RTOL, atol=1e-6 * np.abs(base[key]).max()
        )
    for key in ("reflectance", "light_share", "error_rgb6", "noise_image"):
        np.testing.assert_allclose(twice[key], base[key], rtol=RELIGHT_RTOL, atol=1e-6)


def test_in_memory_relighting_equals_the_written_relit_sample(built):
    out, _, sample = built
    relit = load_sample(relight(sample, NEW_LIGHTS, out / "mem__v0__two"))
    written, half = _arrays(relit), relit["meta"]["storage"]["half"]
    memory = relit_layers(sample, NEW_LIGHTS)
    assert half == ["noise_image", "noise_shading_raw"]
    for key, value in written.items():
        if key in half:  # the noise maps are stored as float16 (issue 45)
            np.testing.assert_allclose(
                value, memory[key], rtol=2.0**-11, atol=2.0**-24, err_msg=key
            )
        else:
            np.testing.assert_array_equal(memory[key], value, err_msg=key)


def test_the_write_threads_write_a_relit_sample_byte_for_byte_as_the_serial_writer(
    built, tmp_path, monkeypatch
):
    """Issue 45: every file of a relit folder (``meta.json`` included: it holds no time) is
    the serial writer's, although the EXR files and previews were encoded by threads."""
    _, _, sample = built
    threaded = relight(sample, NEW_LIGHTS, tmp_path / "threads" / "relit__v0__two")
    monkeypatch.setattr(write_pool, "WRITE_THREADS", 0)
    serial = relight(sample, NEW_LIGHTS, tmp_path / "serial" / "relit__v0__two")
    written = _files(threaded)
    assert len(written) > 20 and "meta.json" in written
    assert written == _files(serial)


def test_random_relight_is_seeded_per_item_and_epoch(built):
    _, _, sample = built
    draw = RandomRelight(seed=3)
    assert draw.lights(2, index=5) == RandomRelight(seed=3).lights(2, index=5)
    assert len({tuple(draw.lights(2, index=5, epoch=e).values()) for e in range(6)}) > 1
    pooled = RandomRelight(seed=3, pool=("cie:FL11", "planck:2500K"))
    assert set(pooled.lights(2, index=0).values()) <= {"cie:FL11", "planck:2500K"}
    item = pooled(sample, index=0)
    assert [li["spectrum"] for li in item["meta"]["lights"]] == list(
        pooled.lights(2, index=0).values()
    )
    assert item["image"].shape == (16, 16, 3)


def test_transport_file_is_recorded_with_its_size(built):
    _, _, sample = built
    meta = json.loads((sample / "meta.json").read_text())
    record = meta["transport"]
    assert TRANSPORT_NAME in meta["files"]
    assert record["bytes"] == (sample / TRANSPORT_NAME).stat().st_size
    assert (
        record["lights"] == 2
        and record["batches"] == 2
        and record["modes"] == ["rgb3", "rgb6", "bands31"]
    )


def test_the_render_record_states_totals_beside_per_batch_counts(built):
    """Issue 46: spp and spectral_spp are totals over the batches (the settings' totals), and
    batch_spp and spectral_batch_spp one batch's."""
    render = json.loads((built[2] / META_NAME).read_text())["render"]
    assert render["spp"] == render["batch_spp"] * render["batches"] == SETTINGS.spp
    total = SETTINGS.spectral_spp or SETTINGS.spp  # no spectral_spp: the spectral pass's is spp
    assert render["spectral_spp"] == render["spectral_batch_spp"] * render["batches"] == total
    assert render["batches"] == SETTINGS.batches == 2


def _written_before_issue_46(sample: Path, parent: Path) -> Path:
    """A copy of *sample* whose meta.json is in the form written before issue 46 (one batch's
    spectral_spp, no spectral_batch_spp), sealed again as that version sealed it."""
    old = parent / sample.name
    shutil.copytree(sample, old)
    meta = json.loads((old / META_NAME).read_text())
    meta["render"]["spectral_spp"] = meta["render"].pop("spectral_batch_spp")
    meta[SEAL_KEY] = meta_seal(meta)
    (old / META_NAME).write_text(canonical_json(meta))
    return old


def _files(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()
    }


def _meta_less_source_hash(data: bytes) -> dict:
    """A relit meta.json without what names its source's bytes (its hash, and the seal)."""
    meta = json.loads(data)
    del meta["render"]["relit"]["from_meta_sha256"], meta[SEAL_KEY]
    return meta


def test_a_sample_written_before_issue_46_relights_as_a_new_one(built, tmp_path):
    _, _, sample = built
    old = _written_before_issue_46(sample, tmp_path / "old")
    assert render_spp(json.loads((old / META_NAME).read_text())["render"]) == render_spp(
        json.loads((sample / META_NAME).read_text())["render"]
    )
    relit_new = _files(relight(sample, NEW_LIGHTS, tmp_path / "a" / "relit__v0__form"))
    relit_old = _files(relight(old, NEW_LIGHTS, tmp_path / "b" / "relit__v0__form"))
    assert relit_old.keys() == relit_new.keys()
    assert [k for k in relit_new if k != META_NAME and relit_old[k] != relit_new[k]] == []
    new_meta = _meta_less_source_hash(relit_new[META_NAME])
    assert _meta_less_source_hash(relit_old[META_NAME]) == new_meta
    # no spectral pass is relit: the record counts the transport's batches and no spectral pass
    source_meta = json.loads((sample / META_NAME).read_text())
    assert "image_spectral" in source_meta["layers"] and "image_spectral" not in new_meta["layers"]
    source = render_spp(source_meta["render"])
    assert source.spectral_spp == SETTINGS.spp
    assert render_spp(new_meta["render"]) == dataclasses.replace(
        source, spectral_spp=None, spectral_batch_spp=None
    )


def test_relight_refuses_bad_requests_before_writing(built, tmp_path):
    out, _, sample = built
    with pytest.raises(DatasetError, match="did you mean 'planck'"):
        relight(sample, {0: "plank:3000K"}, tmp_path / "a")
    with pytest.raises(DatasetError, match="expected an illuminant"):
        relight(sample, {0: "munsell:5R 4/14"}, tmp_path / "a")
    with pytest.raises(DatasetError, match="lights 0..1"):
        relight(sample, {2: "cie:D65"}, tmp_path / "a")
    with pytest.raises(DatasetError, match="the sample itself"):
        relight(sample, {0: "cie:D65"}, sample)
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep me")
    with pytest.raises(DatasetError, match="choose another --out"):
        relight(sample, {0: "cie:D65"}, foreign)
    assert (foreign / "notes.txt").read_text() == "keep me"
    assert not (tmp_path / "a").exists()
    empty = tmp_path / "empty"
    empty.mkdir()
    assert (
        check_sample(relight(sample, {0: "cie:D65"}, empty)) == []
    )  # new or empty, as for dataset


def test_a_sample_without_transport_is_refused(built, tmp_path):
    out, scene, _ = built
    result = render_batches(
        scene, SETTINGS.with_options(modes=("rgb3",), per_light=True, spp=2, batches=1), seed=SEED
    )
    plain = export_sample(out, scene, result, sample_id="plain__v0__two", config=CONFIG, seed=1)
    with pytest.raises(DatasetError, match="--store-transport"):
        relight(plain, {0: "cie:D65"}, tmp_path / "x")


@pytest.mark.parametrize(
    "args, expected",
    [
        (["--light", "0=plank:3000K"], "did you mean 'planck'?"),
        (["--light", "0=cie:LED-RGB9"], "did you mean 'LED-RGB1'"),
        (["--light", "zero=cie:D65"], "expected INDEX=VALUE"),
        (["--light", "0=cie:D65", "--light", "0=cie:A"], "given twice"),
        (["--light", "0=cie:D65", "--power", "0=bright"], "not a number"),
        (["--light", "0=cie:D65", "--power", "5=2"], "lights 0..1"),
    ],
)
def test_cli_bad_input_is_one_line_with_status_2(built, tmp_path, capsys, args, expected):
    from spectrinsic.cli import main

    _, _, sample = built
    before = sorted(p.name for p in sample.iterdir())
    rc = main(["relight", str(sample), *args, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and expected in err, err
    assert "Traceback" not in err and not (tmp_path / "out").exists()
    assert sorted(p.name for p in sample.iterdir()) == before


def test_cli_relights_into_a_checkable_sample(built, tmp_path, capsys):
    from spectrinsic.cli import main

    _, _, sample = built
    out = tmp_path / "relit__v0__two"
    assert main(["-q", "relight", str(sample), "--light", "1=cie:FL11", "--out", str(out)]) == 0
    assert capsys.readouterr().out.strip() == str(out)
    assert check_sample(out) == []
    meta = json.loads((out / "meta.json").read_text())
    assert [li["spectrum"] for li in meta["lights"]] == ["planck:2800K", "cie:FL11"]
    # the same --out again replaces the sample spectrinsic wrote there (never a foreign one)
    assert main(["-q", "relight", str(sample), "--light", "1=cie:FL2", "--out", str(out)]) == 0
    assert json.loads((out / "meta.json").read_text())["lights"][1]["spectrum"] == "cie:FL2"


@pytest.mark.torch
def test_torch_dataset_relights_each_item_on_the_fly(built, torch, tmp_path):
    import shutil

    from spectrinsic.gt_export import torch_dataset

    _, _, sample = built
    shutil.copytree(sample, tmp_path / "ds" / sample.name)
    draw = RandomRelight(
        seed=2, pool=("cie:FL11", "cie:LED-RGB1", "planck:2000K", "daylight:9000K")
    )
    ds = torch_dataset(tmp_path / "ds", keys=("image", "shading"), relight=draw)
    expected = relit_layers(sample, draw.lights(2, index=0))
    item = ds[0]
    assert torch.equal(
        item["image"], torch.from_numpy(np.moveaxis(expected["image"], -1, 0).copy())
    )
    assert item["shading"].shape == (3, 16, 16) and item["sample_id"] == sample.name
    ds.set_epoch(3)
    again = relit_layers(sample, draw.lights(2, index=0, epoch=3))
    assert torch.equal(ds[0]["image"], torch.from_numpy(np.moveaxis(again["image"], -1, 0).copy()))


def test_cheap_augmentation_leaves_out_denoising_and_cameras_only(built):
    _, _, sample = built
    full = relit_layers(sample, NEW_LIGHTS)
    cheap = relit_layers(sample, NEW_LIGHTS, denoise=False, cameras=False)
    assert not any(k.startswith(("image_camera", "image_denoised", "shading_raw")) for k in cheap)
    for key in ("image", "reflectance", "noise_image", "light_share"):
        np.testing.assert_array_equal(cheap[key], full[key], err_msg=key)
    np.testing.assert_array_equal(cheap["shading"], full["shading_raw"])  # undenoised = the raw one


def test_cli_follows_the_out_rule_and_the_lock_of_every_writing_verb(built, tmp_path, capsys):
    """--out inside a dataset is refused, and so is one whose folder another run holds: one
    line, status 2, before any relighting, and nothing written."""
    from spectrinsic.cli import main

    _, _, sample = built

    def refused(out: Path) -> tuple[int, str]:
        rc = main(["-q", "relight", str(sample), "--light", "0=cie:D65", "--out", str(out)])
        return rc, capsys.readouterr().err.strip()

    dataset = tmp_path / "ds"
    dataset.mkdir()
    (dataset / "manifest.json").write_text(json.dumps({"format_version": 1, "config_hash": "h"}))
    rc, err = refused(dataset / "relit__v0__x")
    assert rc == 2 and len(err.splitlines()) == 1 and "inside the dataset folder" in err, err
    assert sorted(p.name for p in dataset.iterdir()) == ["manifest.json"]

    held = tmp_path / "held"
    with held_lock(held) as proc:
        rc, err = refused(held / "relit__v0__x")
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert "in use by another spectrinsic run" in err and f"pid {proc.pid}" in err
    assert not held.exists()  # the holder removed its folder; the refused run wrote nothing


def test_cli_relights_with_a_light_from_a_csv_file(built, tmp_path, monkeypatch):
    """Issue 32: ``--light 0=csv:PATH#COLUMN`` (PATH from the working folder) relights; the
    sample names the file by its file name (no --scene-dir holds it; issue 44: no absolute
    path of the building machine is recorded) and records its SHA-256."""
    import hashlib

    from spectrinsic.cli import main

    _, _, sample = built
    wl = np.arange(380, 781, 5)
    rows = "\n".join(f"{w},{1 + 0.002 * (w - 380):.4f}" for w in wl)
    (tmp_path / "lamp.csv").write_text("wavelength [nm],lamp [W/m2/nm]\n" + rows + "\n")
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "csv__v0__two"
    assert (
        main(["-q", "relight", str(sample), "--light", "0=csv:lamp.csv#lamp", "--out", str(out)])
        == 0
    )
    assert check_sample(out) == []
    meta = json.loads((out / "meta.json").read_text())
    name = "csv:lamp.csv#lamp"
    assert meta["lights"][0]["spectrum"] == name
    digest = hashlib.sha256((tmp_path / "lamp.csv").read_bytes()).hexdigest()
    assert meta["spectrum_files"] == [
        {"spectrum": name, "file": "lamp.csv", "column": "lamp", "sha256": digest}
    ]
    assert str(tmp_path) not in (out / "meta.json").read_text()
