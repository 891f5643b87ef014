"""``LayerSettings``: built once from a dataset config and once from a written sample's
``meta.json``, and the two agree; the working space is checked in one place, with one error."""

from __future__ import annotations

import dataclasses

import pytest

from spectrinsic.errors import DatasetError, WorkingSpaceError
from spectrinsic.gt_export import export_sample
from spectrinsic.gt_export.layers import DEFAULT_CAMERAS, LayerSettings
from spectrinsic.gt_export.relight import settings_of
from spectrinsic.gt_export.sample.meta import read_meta
from spectrinsic.gt_export.sample.working_view import space_of
from spectrinsic.pipeline.presets import DatasetConfig
from spectrinsic.spectra.camera_model import camera_model
from spectrinsic.spectra.working_space import working_space


@pytest.mark.parametrize(
    "options",
    [
        {"working_space": "srgb", "spectral_layers": True, "write_cube": True},
        {"camera": "nikon-d5100-npl", "denoise": False, "working_space": "rec2020"},
    ],
)
def test_a_sample_s_meta_gives_back_the_layer_settings_it_was_written_with(
    tmp_path, one_light_sample, options
):
    """What relight builds from meta.json equals what the build had (its noise id: the
    source's own id, which the build's default ``None`` stands for)."""
    scene, result = one_light_sample
    config = DatasetConfig.from_settings("tiny", width=16, height=16, spp=2, **options)
    built = config.layer_settings()
    folder = export_sample(
        tmp_path, scene, result, built, sample_id="s", config=config.to_dict(), seed=2
    )
    read = settings_of(read_meta(folder).raw)
    assert read == dataclasses.replace(built, noise_id="s")
    assert read.working_space is working_space(options["working_space"])


def test_layer_settings_add_the_camera_chain_s_sensitivities_once():
    nikon = camera_model("nikon-d5100-npl")
    with_it = LayerSettings(cameras=DEFAULT_CAMERAS, camera=nikon)
    assert with_it.cameras == DEFAULT_CAMERAS  # the Nikon's curves are among the defaults
    alone = LayerSettings(cameras=["camera:Sigma SDMerill (NPL)"], camera=nikon)
    assert alone.cameras == ("camera:Sigma SDMerill (NPL)", nikon.sensitivities)
    assert LayerSettings().with_cube(True).cameras == DEFAULT_CAMERAS
    assert LayerSettings().with_cube(False).cameras == ()


def test_an_unknown_working_space_is_one_error_wherever_it_enters():
    """The config option and meta.json name their input; both are the one error type."""
    base = DatasetConfig.from_settings("tiny", width=8, height=8, spp=2)
    with pytest.raises(WorkingSpaceError, match="^--working-space 'cmyk'; expected one of"):
        base.with_options(working_space="cmyk")
    with pytest.raises(WorkingSpaceError, match="^meta.json working_space 'cmyk'; expected"):
        space_of({"working_space": {"name": "cmyk"}})
    with pytest.raises(WorkingSpaceError, match="^working space 7; expected one of"):
        working_space(7)  # type: ignore[arg-type]
    assert issubclass(WorkingSpaceError, DatasetError)  # the CLI's one-line refusal
    assert space_of({}).name == "srgb"  # a sample from before the field existed
