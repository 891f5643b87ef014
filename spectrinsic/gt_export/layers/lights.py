"""The light family: each light's record (SPD colour in every sensor space, share) and the
per-pixel ``light_share`` layer.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ...errors import DatasetError
from ...spectra import get_sensors, get_spectrum, xyz_to_xy

# Responses with the light's white at Y = 1; under D65 with sRGB sensors, the canonical p^{s,c}.
from ...spectra import white_normalised_responses as canonical_responses
from . import irradiance as irr
from .imaging import light_shares
from .records import Layer, LightRecord, SampleInputs, camera_key, make_layer

__all__ = ["light_records", "share_layers"]


def light_records(
    s: SampleInputs, shares: np.ndarray, spaces: Mapping[str, np.ndarray], cameras: Sequence[str]
) -> tuple[LightRecord, ...]:
    white = np.ones(s.wl.size)
    cie = get_sensors("cie1931").on(s.wl)
    records = []
    for i, light in enumerate(s.scene.lights):
        spd = get_spectrum(light.spectrum, data_dir=s.data_dir).on(s.wl)
        colour = {k: canonical_responses(white, spd, c, s.wl) for k, c in spaces.items()}
        xy = xyz_to_xy(canonical_responses(white, spd, cie, s.wl))
        records.append(
            LightRecord(
                index=i,
                name=light.name,
                kind=light.kind,
                spectrum=light.spectrum,
                power=float(light.power),
                position=tuple(map(float, light.position)),
                direction=tuple(map(float, light.direction)),
                size=tuple(map(float, light.size)),
                cutoff_deg=float(light.cutoff_deg),
                radius=float(light.radius),
                xy=(float(xy[0]), float(xy[1])),
                srgb=tuple(float(v) for v in colour["srgb"]),
                camera={camera_key(c): tuple(float(v) for v in colour[c]) for c in cameras},
                share=float(shares[i]),
            )
        )
    return tuple(records)


def _per_light_luminance(s: SampleInputs) -> np.ndarray:
    """``(L, H, W)`` luminance of each light's own render (the reference mode if rendered per
    light, else the per-light share mode)."""
    per_light = s.result.per_light
    lights = s.scene.lights
    if per_light:
        if len(per_light) != len(lights):
            raise DatasetError(
                f"render has {len(per_light)} per-light images but the scene has "
                f"{len(lights)} lights"
            )
        return np.stack(
            [
                np.asarray(pl[s.ref] if s.ref in pl else next(iter(pl.values())), float)[..., 1]
                for pl in per_light
            ]
        )
    if len(lights) == 1:
        return np.asarray(s.result.images[s.ref], float)[None, ..., 1]
    raise DatasetError(
        f"scene {s.scene.name!r} has {len(lights)} lights but the render has no "
        "per-light images; render with per_light=True"
    )


def share_layers(
    s: SampleInputs, w: irr.WhiteRadiance, mask: np.ndarray
) -> tuple[list[Layer], np.ndarray]:
    """Per-pixel share of each light in the light arriving, and each light's share of the
    image's white-surface luminance."""
    y_maps = _per_light_luminance(s)
    share = np.where(w.valid[..., None], irr.share_maps(y_maps), 0.0)
    grey = irr.luminance_of(w)
    weights = share[mask] * grey[mask][:, None]
    totals = weights.sum(axis=0)
    shares = totals / totals.sum() if totals.sum() > 0 else light_shares(y_maps, mask)
    # one light: an (H, W) map, as every single-channel layer is stored
    layer = make_layer(
        "light_share",
        share[..., 0] if share.shape[-1] == 1 else share,
        tuple(f"L{i}" for i in range(len(s.scene.lights))),
        "fraction of the light arriving (white-surface luminance) due to each light "
        "(channel L<i> = meta['lights'][i]); 0 where no surface",
        "lights",
        nonnegative=True,
    )
    return [layer], shares
