"""A probe render: a small, cheap luminance image of a scene, with which the view rule of
generated scenes judges the light a camera actually sees
(:func:`spectrinsic.scenes.generators.view_rule.judge_frame`, issue 47).

The probe is the spectral reference pass (:func:`~spectrinsic.render.spectral.render_spectral`)
with the CIE 1931 curves, at :data:`PROBE_SIZE` pixels along the longer side (the camera's
aspect kept), :data:`PROBE_SPP` samples per pixel and a fixed seed: the same scene on the same
Mitsuba backend always gets the same image. Only the Y channel is returned.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..scenes.model import Scene
from ..spectra import get_sensors
from .settings import PassRequest
from .spectral import render_spectral

__all__ = ["PROBE_DEPTH", "PROBE_SIZE", "PROBE_SPP", "probe_luminance"]

#: Pixels along the probe's longer side, samples per pixel, and path depth (the light of a
#: room is judged, not its fine detail: 32² x 16 spp is about 16 000 paths).
PROBE_SIZE = 32
PROBE_SPP = 16
PROBE_DEPTH = 4
_SEED = 0


def probe_luminance(
    scene: Scene, *, data_dir: str | None = None, variant: str | None = None
) -> np.ndarray:
    """CIE Y ``(H, W)`` of *scene* at probe size (linear; the render's units), rendered on
    *variant*'s backend (:func:`~spectrinsic.render.base.variants.choose_variant`)."""
    cam = scene.camera
    scale = PROBE_SIZE / max(cam.width, cam.height)
    small = replace(
        cam,
        width=max(1, round(cam.width * scale)),
        height=max(1, round(cam.height * scale)),
    )
    out = render_spectral(
        replace(scene, camera=small),
        get_sensors("cie1931", data_dir=data_dir),
        PassRequest(PROBE_SPP, _SEED, PROBE_DEPTH, variant),
        data_dir=data_dir,
    )
    return np.asarray(out.image[..., 1], np.float64)
