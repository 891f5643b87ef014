"""Samples per pixel of a written sample: ``meta.json["render"]``'s counts, in both of its forms.

Every count key of the record is a total over the independent batches, and every per-batch
count is named ``*batch_spp`` (issue 46): ``spp`` and ``batch_spp``, ``spectral_spp`` and
``spectral_batch_spp`` (the spectral reference pass; only where it was rendered), with
``batches`` beside them (absent: one batch). Samples written before issue 46 held one batch's
count under ``spectral_spp`` (the *old form*); they are recognised by a ``spectral_spp`` with
more than one batch and no ``spectral_batch_spp`` (with one batch both forms say the same),
the way ``working_space`` is read as ``srgb`` where it is absent (no format bump: the rest of
the sample is unchanged and every reader reads both forms through :func:`render_spp`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["RenderSpp", "render_spp"]


@dataclass(frozen=True)
class RenderSpp:
    """A sample's samples per pixel (each count ``None`` where the record holds none).

    Attributes
    ----------
    spp
        Total over the batches of every mode's pass (the traversal and the diagonal modes).
    batches
        Independent batches (1 without the ``batches`` key).
    batch_spp
        One batch's count (``spp / batches``).
    spectral_spp
        Total over the batches of the spectral reference pass, ``None`` where it was not
        rendered (a relit sample's: its images are composed from the transport, and its
        record keeps no spectral count).
    spectral_batch_spp
        One batch's count of the spectral pass.
    """

    spp: int | None
    batches: int
    batch_spp: int | None
    spectral_spp: int | None
    spectral_batch_spp: int | None


def _int(record: Mapping[str, Any], key: str) -> int | None:
    value = record.get(key)
    return value if type(value) is int else None


def render_spp(record: Mapping[str, Any]) -> RenderSpp:
    """The counts of ``meta.json["render"]`` *record*, written before issue 46 (a
    ``spectral_spp`` of one batch) or after (totals): the same :class:`RenderSpp` for both."""
    batches = _int(record, "batches") or 1
    spp, spectral = _int(record, "spp"), _int(record, "spectral_spp")
    spectral_batch = _int(record, "spectral_batch_spp")
    if spectral is not None and spectral_batch is None:
        # one batch, or the old form: spectral_spp was one batch's
        spectral, spectral_batch = spectral * batches, spectral
    batch_spp = _int(record, "batch_spp") or (None if spp is None else spp // batches)
    return RenderSpp(spp, batches, batch_spp, spectral, spectral_batch)
