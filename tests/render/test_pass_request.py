"""``PassRequest``: one record of what every pass of a batch shares, checked once."""

from __future__ import annotations

import inspect

import pytest

from spectrinsic.errors import RenderError
from spectrinsic.render.band_path.traversal import render_jobs, render_traversal
from spectrinsic.render.passes import render_diagonal
from spectrinsic.render.passes.aovs import render_aovs
from spectrinsic.render.settings import UINT32_MAX, PassRequest, RenderSettings
from spectrinsic.render.spectral import render_spectral


def test_a_request_is_checked_at_construction():
    with pytest.raises(RenderError, match=r"batch_spp=0; expected a positive integer"):
        PassRequest(0, seed=1)
    with pytest.raises(RenderError, match=r"max_depth=0; expected a positive integer"):
        PassRequest(4, seed=1, max_depth=0)
    with pytest.raises(RenderError, match=r"batch_spp=True"):
        PassRequest(True, seed=1)  # type: ignore[arg-type]
    assert UINT32_MAX == 2**32 - 1


def test_a_batch_s_request_holds_the_per_batch_count_not_the_total():
    settings = RenderSettings(12, modes=("rgb3",), batches=3, max_depth=4, variant="scalar")
    request = PassRequest.of(settings, seed=9)
    assert (request.batch_spp, request.seed, request.max_depth) == (4, 9, 4)
    assert request.variant == "scalar" and request.progress is None
    ticks: list[int] = []
    PassRequest.of(settings, seed=9, progress=ticks.append).tick()
    assert ticks == [1]


@pytest.mark.parametrize(
    "render_pass", [render_diagonal, render_spectral, render_aovs, render_traversal, render_jobs]
)
def test_every_pass_takes_the_request_and_no_loose_sample_count(render_pass):
    params = inspect.signature(render_pass).parameters
    assert "request" in params
    assert not {"spp", "seed", "max_depth", "variant", "progress", "geometry"} & set(params)
