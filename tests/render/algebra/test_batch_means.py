"""merge_batches' metadata: every sample count a total over the batches, every per-batch count
named ``*batch_spp`` (issue 46: one meaning per key of ``meta.json["render"]``)."""

from __future__ import annotations

import numpy as np

from spectrinsic.render.algebra.batch_means import merge_batches
from spectrinsic.render.result import RenderResult


def _batch(seed: int, spectral_spp: int | None) -> RenderResult:
    """One batch as render_scene records it: 3 samples per pixel, *spectral_spp* in the
    spectral pass (``None``: no spectral mode)."""
    image = np.full((2, 2, 3), float(seed), np.float32)
    timing = {"passes": 1, "seconds": 0.5, "per_pass": [0.5]}
    meta = {"spp": 3, "seed": seed, "timings": {"rgb3": timing}}
    if spectral_spp is not None:
        meta["spectral_spp"] = spectral_spp
    return RenderResult(images={"rgb3": image}, raw={"rgb3": image}, meta=meta)


def test_merged_counts_are_totals_beside_their_per_batch_counts():
    merged = merge_batches([_batch(s, 2) for s in (5, 6, 7)]).meta
    assert (merged["spp"], merged["batch_spp"], merged["batches"]) == (9, 3, 3)
    assert (merged["spectral_spp"], merged["spectral_batch_spp"]) == (6, 2)
    assert merged["batch_seeds"] == [5, 6, 7]
    assert merged["timings"]["rgb3"]["passes"] == 3


def test_without_a_spectral_pass_no_spectral_count_is_written():
    merged = merge_batches([_batch(s, None) for s in (1, 2)]).meta
    assert "spectral_spp" not in merged and "spectral_batch_spp" not in merged
    assert merged["spp"] == 6


def test_one_batch_is_its_own_total():
    one = _batch(1, 2)
    assert merge_batches([one]) is one
    assert one.meta["spectral_spp"] == 2 and "spectral_batch_spp" not in one.meta
