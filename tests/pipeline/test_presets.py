"""Presets and config hashes: validation, canonical hashing, what enters the hash."""

from __future__ import annotations

import hashlib
import json

import pytest

from spectrinsic.errors import DatasetError, SpectrinsicError
from spectrinsic.pipeline.presets import PRESETS, DatasetConfig, get_preset, hashed_versions


def test_presets_exist_and_scale_up():
    assert list(PRESETS) == ["preview", "default", "paper"]
    pixels_spp = [c.width * c.height * c.render.spp for c in PRESETS.values()]
    assert pixels_spp == sorted(pixels_spp) and len(set(pixels_spp)) == 3


def test_default_preset_renders_what_the_ground_truth_needs():
    cfg = get_preset("default")
    assert set(cfg.render.modes) == {"spectral", "rgb3", "rgb6", "bands31"}
    assert cfg.render.per_light  # illuminant map of two-light scenes
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
    from spectrinsic.render.algebra.modes import RENDER_MODES

    assert "gauss3" in RENDER_MODES
    cfg = get_preset("preview").with_options(modes=tuple(RENDER_MODES), share_mode="gauss3")
    assert cfg.render.modes == tuple(RENDER_MODES) and cfg.render.share_mode == "gauss3"
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
            return {
                **real(dists, python=python),
                **{k: v for k, v in changes.items() if k in dists},
            }

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
    assert (
        base.with_options(spp=base.render.spp + base.render.batches).config_hash()
        != base.config_hash()
    )
    assert base.with_options(seed=1).config_hash() != base.config_hash()
    assert base.with_options(spectral_spp=base.render.batches).config_hash() != base.config_hash()
    assert base.with_options(modes=("rgb3",)).config_hash() != base.config_hash()


def test_config_is_frozen():
    cfg = DatasetConfig.from_settings("x", width=8, height=8, spp=1)
    with pytest.raises(AttributeError):
        cfg.render.spp = 2  # type: ignore[misc]
    with pytest.raises(AttributeError):
        cfg.width = 2  # type: ignore[misc]


@pytest.mark.parametrize("name", ["preview", "default", "paper"])
def test_the_written_record_rebuilds_the_same_config(name):
    """The flat settings a sample records (``meta.json``, manifest) give back the config with
    its embedded render settings: no setting is lost between the record and the renderer."""
    cfg = get_preset(name, seed=3).with_options(direct=True, noise_target=0.05)
    record = cfg.settings()
    rebuilt = DatasetConfig.from_settings(cfg.preset, **{**record, "cameras": cfg.cameras})
    assert rebuilt == cfg and rebuilt.config_hash() == cfg.config_hash()
    assert (
        rebuilt.render.spp == record["spp"]
        and rebuilt.render.batch_spp * record["batches"] == record["spp"]
    )


def test_render_settings_errors_read_as_dataset_settings():
    with pytest.raises(DatasetError, match="dataset setting spp=3 with batches=2"):
        get_preset("preview").with_options(spp=3)
    with pytest.raises(DatasetError, match="dataset setting spectral_spp=3 with batches=2"):
        get_preset("preview").with_options(spectral_spp=3)
    with pytest.raises(DatasetError, match="unknown dataset setting.*'aovs'"):
        get_preset("preview").with_options(aovs=False)
