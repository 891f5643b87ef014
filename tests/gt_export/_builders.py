"""Samples for the gt_export tests: one written with its per-light transport (``dataset
--store-transport``'s way), the source of the relighting, storage and layer tests; and a
sample's seal renewed after a test edited its files on purpose.

A helper module, not a conftest: its function takes arguments (scene, settings, seed, id), and
tests/test_test_layout.py checks only ``test_*.py`` files.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path

from spectrinsic.gt_export import export_sample
from spectrinsic.gt_export.layers import LayerSettings
from spectrinsic.gt_export.sample import HASHES_KEY, SEAL_KEY, file_sha256, meta_seal
from spectrinsic.render import RenderSettings
from spectrinsic.render.algebra.light_transport import LightTransport
from spectrinsic.render.result import RenderResult
from spectrinsic.render.transport_render import render_transport_batches
from spectrinsic.scenes.model import Scene

__all__ = ["render_transport_sample", "renew_seal"]


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


def renew_seal(folder: Path) -> None:
    """Hashes and seal of *folder*'s ``meta.json`` renewed over its files as they are now (what
    a writer bug would leave, unlike damage)."""
    meta = json.loads((folder / "meta.json").read_text())
    meta[HASHES_KEY] = {rel: file_sha256(folder / rel) for rel in meta[HASHES_KEY]}
    meta.pop(SEAL_KEY)
    meta[SEAL_KEY] = meta_seal(meta)
    (folder / "meta.json").write_text(json.dumps(meta))
