"""What one band-path traversal gives per value set: :class:`TransportOutput`.

Every array is for **unit emission** in every band of every light: ``transport[l, ..., k]`` is
light l's ``∫ radiance S_k`` per unit ``E_{l,k}``, and an image is ``Σ_l E_{l,k} ·
transport[l, ..., k]`` with the lights' channel values ``E_{l,k}`` (Eq. 5.2, :func:`compose`),
so each light's share is exact and the shares sum to the total.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ...errors import RenderError

__all__ = [
    "TransportOutput",
    "compose",
    "light_shares",
    "sum_lights",
]


def light_shares(parts: np.ndarray, emission: np.ndarray) -> np.ndarray:
    """``(L, ..., K)`` float32 each light's share ``parts_l ∘ E_l`` of *parts* ``(L, ..., K)``
    (``(L, H, W, K)`` images, or ``(L, N, K)`` pixels) under channel values *emission*
    ``(L, K)``, multiplied in float32 (the values rounded to float32 first, as a float32 render
    would use them): one product per value, the same in every kernel, and no float64 copy of
    the transport (the relighting's main cost)."""
    values = np.asarray(parts, np.float32)
    e = np.asarray(emission, np.float64).astype(np.float32)
    return np.multiply(values, e.reshape(e.shape[0], *([1] * (values.ndim - 2)), e.shape[1]))


def sum_lights(shares: np.ndarray, lights: Sequence[int] | None = None) -> np.ndarray:
    """``(H, W, K)`` float32 sum of the *lights*' (default all) float32 *shares* in float64,
    as :func:`~spectrinsic.render.render_scene` sums per-light renders."""
    chosen = list(range(shares.shape[0])) if lights is None else [int(j) for j in lights]
    if len(chosen) == 2:
        # one float32 addition equals the float64 sum rounded to float32, bit for bit (double
        # rounding is innocuous for one operation when 53 >= 2 * 24 + 2), without the copies
        return np.add(shares[chosen[0]], shares[chosen[1]], dtype=np.float32)
    return np.sum(shares[chosen], axis=0, dtype=np.float64).astype(np.float32)


def compose(
    parts: np.ndarray, emission: np.ndarray, lights: Sequence[int] | None = None
) -> np.ndarray:
    """``(H, W, K)`` float32 image of the *lights* (default all) from per-light *parts*
    ``(L, H, W, K)`` for unit emission under channel values *emission* ``(L, K)``: the sum of
    their shares (:func:`light_shares`, :func:`sum_lights`), the one composition of the transport
    and of every part (Eq. 5.2 per channel)."""
    return sum_lights(light_shares(parts, emission), lights)


@dataclass(frozen=True, eq=False)
class TransportOutput:
    """Per-light band transport of one value set from one traversal.

    Attributes
    ----------
    transport
        ``(L, H, W, K)`` float32 per-light transport (module docstring).
    direct
        The same for direct light only (path depth 2), or ``None`` when not asked for.
    emission
        ``(L, K)`` float64 the lights' channel values ``E_{l,k}`` (:class:`ChannelValues`).
    parts
        :data:`~spectrinsic.render.result.PARTS` name -> ``(L, H, W, K)`` float32, the parts
        the traversal rendered.
    """

    transport: np.ndarray
    direct: np.ndarray | None
    emission: np.ndarray
    parts: dict[str, np.ndarray] = field(default_factory=dict)

    def image(self, lights: Sequence[int] | None = None, *, direct: bool = False) -> np.ndarray:
        """``(H, W, K)`` float32 image of the *lights* (default all): the sum of their shares
        ``E_{l,k} · transport`` (:func:`compose`)."""
        t = self.direct if direct else self.transport
        if t is None:
            raise RenderError("no direct-only transport was rendered")
        return compose(t, self.emission, lights)

    def part_image(self, part: str, lights: Sequence[int] | None = None) -> np.ndarray | None:
        """``(H, W, K)`` float32 image of *part* (:data:`~spectrinsic.render.result.PARTS`) for the *lights* (default all),
        composed as :meth:`image` composes the transport (so both agree bit for bit where all
        light is specular), or ``None`` where the traversal did not render it."""
        held = self.parts.get(part)
        return None if held is None else compose(held, self.emission, lights)
