"""Presets and config hashes: validation, canonical hashing, what enters the hash."""

from __future__ import annotations

import hashlib
import json

import pytest

from spectrinsic.errors import SpectrinsicError
from spectrinsic.pipeline.presets import PRESETS, DatasetConfig, get_preset, hashed_versions


def test_presets_exist_and_scale_up():
    assert list(PRESETS) == ["preview", "default", "paper"]
    pixels_spp = [c.width * c.height * c.spp for c in PRESETS.values()]
    assert pixels_spp == sorted(pixels_spp) and len(set(pixels_spp)) == 3


def test_default_preset_renders_what_the_ground_truth_needs():
    cfg = get_preset("default")
    assert set(cfg.modes) == {"spectral", "rgb3", "rgb6", "bands31"}
    assert cfg.per_light  # illuminant map of two-light scenes
    assert cfg.resolved_cameras()  # camera views need the bands31 cube


def test_unknown_preset_suggests_a_close_name():
    with pytest.raises(SpectrinsicError, match="did you mean 'preview'"):
        get_preset("previw")


@pytest.mark.parametrize(
    "bad", [{"spp": 0}, {"width": -1}, {"modes": ()}, {"modes": ("rgb9",)}, {"seed": -2}]
)
def test_invalid_settings_raise(bad):
    with pytest.raises(SpectrinsicError):
        get_preset("preview").with_options(**bad)


def test_every_registered_render_mode_validates():
    """The config accepts exactly the render package's registry (gauss3 included), no list of
    its own."""
    from spectrinsic.render.modes import RENDER_MODES

    assert "gauss3" in RENDER_MODES
    cfg = get_preset("preview").with_options(modes=tuple(RENDER_MODES), share_mode="gauss3")
    assert cfg.modes == tuple(RENDER_MODES) and cfg.share_mode == "gauss3"
    with pytest.raises(SpectrinsicError, match="did you mean 'gauss3'"):
        get_preset("preview").with_options(modes=("gaus3",))


def test_with_options_rejects_unknown_settings():
    with pytest.raises(SpectrinsicError, match="unknown dataset setting"):
        get_preset("preview").with_options(samples_per_pixel=3)


def test_config_hash_is_sha256_of_canonical_json():
    cfg = get_preset("default", seed=7)
    record = cfg.to_dict()
    # Independent computation: sorted keys, compact separators, UTF-8.
    text = json.dumps(record, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    assert cfg.config_hash() == hashlib.sha256(text.encode("utf-8")).hexdigest()
    assert record["software"] == hashed_versions()
    assert "spectrinsic-pixels" in record["software"] and "mitsuba" in record["software"]


def test_config_hash_ignores_versions_that_do_not_change_pixels(monkeypatch):
    """A numpy or colour-science patch release, or any other package, keeps the hash; a new
    Mitsuba or a bumped pixel version changes it."""
    import spectrinsic.pipeline.presets as presets
    import spectrinsic.provenance as provenance

    real = provenance.software_versions
    base = get_preset("preview").config_hash()

    def bumped(**changes):
        def fake(dists, *, python=True):
            return {**real(dists, python=python), **{k: v for k, v in changes.items() if k in dists}}
        return fake

    installed = real(("numpy", "colour-science"), python=False)
    patch = {k: installed[k] + ".99" for k in installed}  # same major/minor, new patch
    monkeypatch.setattr(provenance, "software_versions", bumped(**patch, scipy="99.0"))
    assert get_preset("preview").config_hash() == base
    monkeypatch.setattr(provenance, "software_versions", bumped(mitsuba="3.9.99"))
    assert get_preset("preview").config_hash() != base
    monkeypatch.setattr(provenance, "software_versions", real)
    monkeypatch.setattr(presets, "PIXELS_VERSION", presets.PIXELS_VERSION + 1)
    assert get_preset("preview").config_hash() != base


def test_hash_changes_with_output_settings_only():
    base = get_preset("preview")
    assert base.config_hash() == get_preset("preview").config_hash()
    assert base.with_options(spp=base.spp + base.batches).config_hash() != base.config_hash()
    assert base.with_options(seed=1).config_hash() != base.config_hash()
    assert base.with_options(modes=("rgb3",)).config_hash() != base.config_hash()


def test_config_is_frozen():
    cfg = DatasetConfig(preset="x", width=8, height=8, spp=1)
    with pytest.raises(AttributeError):
        cfg.spp = 2  # type: ignore[misc]
