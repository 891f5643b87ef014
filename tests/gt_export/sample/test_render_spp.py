"""The sample counts of ``meta.json["render"]`` read the same from both of its forms: written
before issue 46 (``spectral_spp`` one batch's) and after (``spectral_spp`` the total, with
``spectral_batch_spp``)."""

from __future__ import annotations

from spectrinsic.gt_export.sample.render_spp import RenderSpp, render_spp

#: The preview preset with ``--spp 4 --spectral-spp 2``, as written now (2 batches).
NEW = {"spp": 4, "batches": 2, "batch_spp": 2, "spectral_spp": 2, "spectral_batch_spp": 1}
#: The same sample written before issue 46: one batch's spectral count, no per-batch key.
OLD = {"spp": 4, "batches": 2, "batch_spp": 2, "spectral_spp": 1}


def test_both_forms_give_the_same_totals():
    expected = RenderSpp(spp=4, batches=2, batch_spp=2, spectral_spp=2, spectral_batch_spp=1)
    assert render_spp(NEW) == expected
    assert render_spp(OLD) == expected


def test_one_batch_reads_the_same_in_both_forms():
    one = {"spp": 8, "spectral_spp": 4}
    assert render_spp(one) == RenderSpp(8, 1, 8, 4, 4)


def test_a_relit_record_without_a_spectral_pass_has_no_spectral_count():
    counts = render_spp({"spp": 6, "batches": 3, "batch_spp": 2})
    assert counts == RenderSpp(6, 3, 2, None, None)
