"""The record a render returns: arrays and metadata, no live renderer (numpy only: the render
records sit below ``algebra/``; the ``meta`` record is made by
:mod:`spectrinsic.render.scene_render`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import RenderError

__all__ = ["METAL_WHITE", "PARTS", "SPECULAR", "RenderResult"]

#: Glossy scenes' part of the transport: the light whose first camera-ray vertex went through a
#: non-diffuse lobe (coat reflection, metal, glass), with everything those lobes reflect; 0 in
#: matte scenes (it becomes the ``specular`` layer).
SPECULAR = "specular"
#: Metals' white-surface radiance at their first hits times their coverage, ``c_metal · E_k / π``
#: (not part of the transport; it keeps the shading of metal pixels defined where the diffuse
#: albedo is 0; :mod:`spectrinsic.render.band_path.kernel`).
METAL_WHITE = "metal_white"
#: The parts a band-path traversal splits off beside its transport, in the order of its AOV
#: channels (:func:`~spectrinsic.render.band_path.integrator.aov_channels`), and the one letter
#: of each: its AOV channels are ``<letter lower-case><light>_<band>`` and its layers in
#: ``transport.exr`` ``<letter><light>...`` (:mod:`spectrinsic.gt_export.sample.transport_exr`;
#: the transport's own are ``t`` and ``L``). Each is ``(L, H, W, K)`` per unit emission,
#: composed as the transport is; every record below the traversal (``TransportOutput``,
#: ``RenderResult.parts``, ``LightTransport.parts``, the batches, the file) holds the parts by
#: these names.
PARTS: dict[str, str] = {SPECULAR: "S", METAL_WHITE: "W"}


@dataclass(frozen=True, eq=False)
class RenderResult:
    """Images of one scene in several render modes, with ground-truth helper maps.

    Attributes
    ----------
    images
        mode -> ``(H, W, 3)`` float32 linear CIE 1931 XYZ (``∫ L x̄ dλ`` etc., λ in nm).
    raw
        mode -> ``(H, W, K)`` float32 raw channels (the ``(H, W, 31)`` band cube, the 6 Gaussian
        sensors, ...), ``∫ L S_k dλ`` under each mode's diagonal approximation.
    per_light
        One dict mode -> ``(H, W, 3)`` XYZ per scene light (empty unless asked for);
        ``images[mode]`` is exactly their sum.
    direct
        mode -> ``(H, W, 3)`` XYZ of direct light only (path depth 2), for the energy ratio r of
        Eq. 5.8 (empty unless asked for).
    aovs
        ``coverage`` ``(H, W, M)`` float32, ``material_id`` / ``object_id`` ``(H, W)`` int32 (-1
        background), ``depth`` ``(H, W)`` float32, ``normals`` ``(H, W, 3)`` float32, ``mask``
        ``(H, W)`` bool; see :func:`spectrinsic.render.passes.aovs.render_aovs` (empty unless asked).
    meta
        Variants, spp, seed, max_depth, sensors and XYZ matrices per mode, wavelength grid,
        timings (seconds per pass), Mitsuba version; with batches also ``batches``,
        ``batch_spp`` and ``batch_seeds``. ``spp`` and ``spectral_spp`` (the spectral pass's)
        are totals over the batches, ``batch_spp`` and ``spectral_batch_spp`` one batch's
        (:mod:`spectrinsic.gt_export.sample.render_spp` reads samples written before).
    batch_raw
        Per independent batch (:func:`spectrinsic.render.render_batches`), mode -> ``(H, W, K)``
        float32 raw channels of that batch alone; ``raw`` is their mean. Empty for a single
        batch.
    transport
        With the single-traversal integrator, mode -> ``(L, H, W, K)`` float32 per-light band
        transport for unit emission, composed to ``raw`` by Eq. 5.2
        (:mod:`spectrinsic.render.algebra.shares`). Empty otherwise.
    parts
        Single traversal: :data:`PARTS` name -> mode -> ``(H, W, K)`` float32 raw channels of
        that part, summed over the lights as ``raw`` is; only the parts the scene has.
    part_transport
        The per-light parts behind ``parts`` as ``transport`` is behind ``raw`` (part name ->
        mode -> ``(L, H, W, K)`` float32 for unit emission); empty without them.
    """

    images: dict[str, np.ndarray]
    raw: dict[str, np.ndarray]
    per_light: tuple[dict[str, np.ndarray], ...] = ()
    direct: dict[str, np.ndarray] = field(default_factory=dict)
    aovs: dict[str, np.ndarray] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)
    batch_raw: tuple[dict[str, np.ndarray], ...] = ()
    transport: dict[str, np.ndarray] = field(default_factory=dict)
    parts: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    part_transport: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)

    @property
    def specular(self) -> dict[str, np.ndarray]:
        """``parts["specular"]``: mode -> ``(H, W, K)`` raw specular part (empty: matte scene)."""
        return self.parts.get(SPECULAR, {})

    def energy_ratio(self, mode: str) -> float:
        """r = Σ_x ‖p¹(x)‖ / Σ_x ‖p^∞(x)‖ (Eq. 5.8) on *mode*'s XYZ, from the direct-only render."""
        if mode not in self.direct:
            raise RenderError(f"no direct-only render of mode {mode!r}; render with direct=True")
        full = float(np.linalg.norm(self.images[mode].astype(np.float64), axis=-1).sum())
        one = float(np.linalg.norm(self.direct[mode].astype(np.float64), axis=-1).sum())
        return one / full if full > 0 else float("nan")
