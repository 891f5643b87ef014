"""Layers stored as their factors (issue 45): ``reflectance_bands`` as the coverage times a
per-material band table, the denoised ``image_bands`` and every identity's residual rebuilt
from the stored layers, by the readers, bit for bit.

Independent values: the layers computed in memory by :func:`compute_ground_truth` from the same
render (what the writer stored before issue 45), and a sample rewritten in that old form.
"""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import check_sample, export_sample, load_sample
from spectrinsic.gt_export.formats.exr import read_exr, read_exr_attributes, write_exr
from spectrinsic.gt_export.layers import LayerSettings, compute_ground_truth, identities
from spectrinsic.gt_export.layers.settings import DEFAULT_CAMERAS
from spectrinsic.gt_export.sample.layer_storage import COVERAGE_LAYER
from spectrinsic.gt_export.sample.stored_layers import stored_layers
from spectrinsic.render import RenderSettings, render_batches
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene
from spectrinsic.scenes.textures import basis_name, make_texture
from tests.gt_export._builders import renew_seal

#: The layers every sample here gets: the default cameras, denoised, per band.
SETTINGS = LayerSettings(cameras=DEFAULT_CAMERAS, denoise=True, spectral_layers=True)

#: What the writer now stores as factors in a denoised sample with spectral layers.
FACTORED = {
    "reflectance_bands": "coverage_table",
    "image_bands": "band_image",
    "residual_bands": "identity_residual",
    "residual": "identity_residual",
    "residual_raw": "identity_residual",
}
BASIS = ("munsell:5R 4/14", "munsell:5G 6/8", "munsell:7.5PB 3/10")


def _textured_scene() -> Scene:
    """A 2 × 2 spectrally textured quad (noise over three Munsell chips, 8 × 8 texels) seen
    head-on with background around it, lit by a D65 distant light and a 3000 K point light."""
    mats = tuple(Material(basis_name("wood", b), s) for b, s in enumerate(BASIS))
    v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0.0]])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    texture = make_texture("wood", (0, 1, 2), "noise", 8, seed=2)
    return Scene(
        "texquad",
        (Mesh("quad", v, f, np.zeros(2, np.int64), 0, texture=texture),),
        mats,
        (
            Light("directional", "cie:D65", 3.0, direction=(0.0, 0.0, -1.0)),
            Light("point", "planck:3000K", 4.0, position=(0.5, 0.5, 2.0)),
        ),
        Camera((0, 0, 3.0), (0, 0, 0), (0, 1, 0), 45.0, 16, 16),
    )


def _export(root, scene):
    settings = RenderSettings(
        2, max_depth=3, modes=("rgb3", "bands31"), per_light=True, share_mode="rgb3", batches=2
    )
    result = render_batches(scene, settings, seed=3)
    sample = export_sample(
        root,
        scene,
        result,
        SETTINGS,
        sample_id=f"{scene.name}__v0__x",
        config={"test": "layer_storage"},
        seed=3,
    )
    gt = compute_ground_truth(scene, result, SETTINGS)
    return sample, gt, result


@pytest.fixture(scope="module")
def textured(tmp_path_factory):
    return _export(tmp_path_factory.mktemp("textured"), _textured_scene())


@pytest.fixture(scope="module")
def room(tmp_path_factory, make_room):
    return _export(tmp_path_factory.mktemp("room"), make_room(size=12))


@pytest.fixture(params=["textured", "room"])
def written(request):
    """A textured quad with background, and an untextured room, both denoised."""
    return request.getfixturevalue(request.param)


def test_factored_layers_are_not_stored_and_load_back_bit_for_bit(written):
    sample, gt, _ = written
    meta = json.loads((sample / "meta.json").read_text())
    forms = meta["storage"]["layers"]
    assert {k: forms.get(k) for k in FACTORED} == FACTORED
    stored = read_exr(sample / "spectral.exr")
    assert "reflectance_bands" not in stored and "residual_bands" not in stored
    assert stored[COVERAGE_LAYER].shape == (16 if "texquad" in sample.name else 12,) * 2 + (
        len(gt.band_albedos),
    )
    loaded = load_sample(sample)
    half = meta["storage"]["half"]
    assert half == ["noise_image", "noise_shading_raw"]  # estimates of two batches' spread
    for key, layer in gt.layers.items():
        value = loaded[key] if key != "mask" else loaded[key].astype(np.float32)
        if key in half:  # estimates outside every identity, float16: 2**-11, subnormals 2**-24
            np.testing.assert_allclose(value, layer.data, rtol=2.0**-11, atol=2.0**-24)
        else:  # every other layer, bit for bit
            assert np.array_equal(value, layer.data), key
    # the table is each material's band albedo, and reflectance_bands is coverage @ table
    table = json.loads(
        read_exr_attributes(sample / "spectral.exr")["spectrinsic.table.reflectance_bands"]
    )
    np.testing.assert_array_equal(np.asarray(table), gt.band_albedos)


def test_textured_reflectance_bands_mix_the_basis_by_the_texel_weights(textured):
    """Where one texel covers a whole pixel, its band reflectance is that texel's convex mix
    of the three basis materials' band albedos (no coverage fringe)."""
    sample, gt, result = textured
    coverage = np.asarray(result.aovs["coverage"], np.float64)
    whole = np.isclose(coverage.sum(-1), 1.0)
    refl = load_sample(sample, layers=["reflectance_bands"])["reflectance_bands"]
    mixed = coverage[whole] @ gt.band_albedos
    assert whole.sum() > 100 and (coverage[whole] > 0).sum(-1).max() > 1  # textured pixels
    np.testing.assert_allclose(refl[whole], mixed, rtol=1e-6, atol=1e-7)


def test_check_passes_on_the_compact_form_and_finds_a_tampered_table(written, tmp_path):
    sample, _, _ = written
    assert check_sample(sample) == []
    copy = tmp_path / sample.name
    shutil.copytree(sample, copy)
    path = copy / "spectral.exr"
    arrays = read_exr(path)
    header = read_exr_attributes(path)
    key = "spectrinsic.table.reflectance_bands"
    table = np.asarray(json.loads(header[key]))
    table[0, 10] *= 1.01  # one band of one material, 1 % brighter
    order = json.loads(header["spectrinsic.channels"])
    write_exr(
        path,
        arrays,
        channel_names=order,
        attributes={key: json.dumps(table.tolist()), "spectrinsic.sample": copy.name},
    )
    problems = check_sample(copy)
    assert any("spectral.exr" in p and "SHA-256" in p for p in problems), problems
    with pytest.raises(DatasetError, match="SHA-256"):
        load_sample(copy, layers=["reflectance_bands"])
    renew_seal(copy)  # the file's hash renewed too: the rebuilt layer's own hash still differs
    problems = check_sample(copy)
    assert any("'reflectance_bands' rebuilt" in p and "SHA-256" in p for p in problems), problems


def _as_old_form(sample, gt, dest):
    """*sample* rewritten as before issue 45: every layer stored in full, no storage record,
    hashes and seal renewed."""
    shutil.copytree(sample, dest)
    meta = json.loads((dest / "meta.json").read_text())
    groups: dict[str, dict] = {}
    for layer in gt.layers.values():
        groups.setdefault(f"{layer.group}.exr", {})[layer.name.split("/", 1)[0]] = layer
    for file, members in groups.items():
        write_exr(
            dest / file,
            {k: v.data for k, v in members.items()},
            channel_names={k: v.channels for k, v in members.items()},
        )
    del meta["storage"]
    (dest / "meta.json").write_text(json.dumps(meta))
    renew_seal(dest)
    return dest


def test_an_old_form_sample_loads_and_checks_as_before(written, tmp_path):
    sample, gt, _ = written
    old = _as_old_form(sample, gt, tmp_path / sample.name)
    assert check_sample(old) == []
    loaded, compact = load_sample(old), load_sample(sample)
    for key, layer in gt.layers.items():
        value = layer.data if layer.data.dtype != bool else layer.data.astype(np.float32)
        assert np.array_equal(loaded[key].astype(value.dtype), value), key  # as written
        assert loaded[key].shape == compact[key].shape, key
    # the compact spectral file is the smaller one
    assert (sample / "spectral.exr").stat().st_size < 0.75 * (old / "spectral.exr").stat().st_size


def test_a_layer_its_factors_do_not_rebuild_exactly_is_stored_in_full(written):
    """One value of the residual off by one float32 step: the writer keeps it in full."""
    import dataclasses

    _, gt, result = written
    layers = dict(gt.layers)
    res = layers["residual_bands"].data.copy()
    res.flat[7] = np.nextafter(res.flat[7], np.float32(np.inf))
    layers["residual_bands"] = dataclasses.replace(layers["residual_bands"], data=res)
    changed = dataclasses.replace(gt, layers=layers)
    stored = stored_layers(changed, result.aovs["coverage"], identities(changed))
    assert "residual_bands" not in stored.forms
    assert np.array_equal(stored.arrays["spectral.exr"]["residual_bands"], res)
    assert stored.forms["reflectance_bands"] == "coverage_table"  # the others unchanged


def test_check_finds_a_wrong_factor_by_the_rebuilt_layers_sha256(room, tmp_path):
    """``shading_bands`` 0.1 % too bright, file hashes and seal renewed (a writer bug, not
    damage): the rebuilt ``image_bands`` and residual absorb it, so the identity holds, but
    they are not the layers the writer computed."""
    sample, _, _ = room
    copy = tmp_path / sample.name
    shutil.copytree(sample, copy)
    path = copy / "spectral.exr"
    arrays, header = read_exr(path), read_exr_attributes(path)
    arrays["shading_bands"] = arrays["shading_bands"] * np.float32(1.001)
    key = "spectrinsic.table.reflectance_bands"
    write_exr(
        path,
        arrays,
        channel_names=json.loads(header["spectrinsic.channels"]),
        attributes={key: header[key]},
    )
    renew_seal(copy)
    problems = check_sample(copy)
    assert "layer 'image_bands' rebuilt from its stored factors does not match its SHA-256" in (
        "\n".join(problems)
    ), problems
    with pytest.raises(DatasetError, match=r"\['image_bands'\] rebuilt .* SHA-256"):
        load_sample(copy, layers=["image_bands"])


def test_an_unknown_form_or_wrong_terms_are_refused_in_one_line(room, tmp_path):
    sample, _, _ = room
    copy = tmp_path / sample.name
    shutil.copytree(sample, copy)
    meta = json.loads((copy / "meta.json").read_text())
    meta["storage"]["layers"]["residual_bands"] = "zip-magic"
    (copy / "meta.json").write_text(json.dumps(meta))
    renew_seal(copy)
    with pytest.raises(DatasetError, match=r"storage\.layers\.residual_bands: 'zip-magic'"):
        load_sample(copy)
    assert any("zip-magic" in p for p in check_sample(copy))
    meta["storage"]["layers"]["residual_bands"] = "identity_residual"
    meta["storage"]["terms"]["residual_bands"] = ["image_bands"]  # a residual of one term
    (copy / "meta.json").write_text(json.dumps(meta))
    renew_seal(copy)
    with pytest.raises(DatasetError, match=r"storage\.terms: .* as many as its form takes"):
        load_sample(copy, layers=["residual_bands"])
