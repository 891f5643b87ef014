"""Issue 36, cause 4 (first half): a relit sample keeps its base sample's reference mode.

In the preview preset the reference ``image`` is the ``spectral`` render, but the stored
transport is diagonal (``rgb3``): relighting gave a variant whose reference mode had switched
to ``rgb3`` (11 layers changed relighting with the sample's own spectra, shading by up to 67.5
of 208.6). Now ``relight`` refuses such a sample in one line, and ``dataset --relight N`` with
such modes is refused before the first sample.
"""

from __future__ import annotations

import json

import pytest

from spectrinsic.cli import main
from spectrinsic.errors import DatasetError
from spectrinsic.pipeline.presets import DatasetConfig
from tests.conftest import QUAD_YAML, TINY_BUILD, one_line_error

TINY = {"width": 8, "height": 8, "spp": 2, "max_depth": 3}


def test_relighting_a_preview_sample_is_refused_not_switched_to_rgb3(tmp_path, capsys):
    (tmp_path / "s.yaml").write_text(QUAD_YAML)
    ds = tmp_path / "ds"
    argv = ["-q", "dataset", *TINY_BUILD, "--scenes", str(tmp_path / "s.yaml"), "--store-transport"]
    assert main([*argv, "--out", str(ds)]) == 0, capsys.readouterr().err
    (sample,) = [p.parent for p in ds.glob("*/meta.json")]
    assert json.loads((sample / "meta.json").read_text())["reference_mode"] == "spectral"
    out = tmp_path / "relit"
    rc = main(["-q", "relight", str(sample), "--light", "0=cie:D65", "--out", str(out)])
    assert rc == 2
    one_line_error(capsys, "'spectral'", "cannot relight")
    assert not out.exists()
    # and a build that would make such variants is refused before its first sample
    rc = main([*argv, "--relight", "1", "--out", str(tmp_path / "ds2")])
    assert rc == 2
    one_line_error(capsys, "--relight 1", "'spectral'")
    assert not (tmp_path / "ds2").exists()


def test_the_plan_allows_relighting_where_the_reference_is_stored():
    DatasetConfig.from_settings(
        "tiny", **TINY, modes=("bands31", "rgb3"), store_transport=True, relight=2
    )
    with pytest.raises(DatasetError, match="'spectral'"):
        DatasetConfig.from_settings(
            "tiny", **TINY, modes=("spectral", "rgb3"), store_transport=True, relight=2
        )


def test_the_preview_relight_refusal_says_which_samples_it_is_about():
    """Issue 47: the refusal names the matte samples' spectral reference and the glossy ones'
    diagonal reference, instead of saying every sample's reference is the spectral render."""
    from spectrinsic.errors import DatasetError
    from spectrinsic.pipeline.presets import get_preset

    with pytest.raises(DatasetError) as info:
        get_preset("preview").with_options(store_transport=True, relight=1)
    message = str(info.value)
    assert "a matte sample's reference image is the 'spectral' render" in message
    assert "only glossy samples take 'rgb3' as reference" in message
