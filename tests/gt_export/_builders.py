"""A sample written with its per-light transport (``dataset --store-transport``'s way), the
source of the relighting, storage and layer tests.

A helper module, not a conftest: its function takes arguments (scene, settings, seed, id), and
tests/test_test_layout.py checks only ``test_*.py`` files.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from spectrinsic.gt_export import export_sample
from spectrinsic.gt_export.layers import LayerSettings
from spectrinsic.render import RenderSettings
from spectrinsic.render.algebra.light_transport import LightTransport
from spectrinsic.render.result import RenderResult
from spectrinsic.render.transport_render import render_transport_batches
from spectrinsic.scenes.model import Scene

__all__ = ["render_transport_sample"]


def render_transport_sample(
    out: Path,
    scene: Scene,
    settings: RenderSettings,
    *,
    seed: int,
    sample_id: str,
    config: Mapping[str, object],
    layers: LayerSettings | None = None,
) -> tuple[Path, LightTransport, RenderResult]:
    """*scene* rendered with its transport (:func:`render_transport_batches`, *settings*,
    *seed*) and written with it as sample *sample_id* in *out* (:func:`export_sample`, with
    *layers* and *config*): the sample folder, the transport and the render."""
    transport, result = render_transport_batches(scene, settings, seed=seed)
    sample = export_sample(
        out, scene, result, layers, sample_id=sample_id, config=config, seed=seed,
        transport=transport,
    )  # fmt: skip
    return sample, transport, result
