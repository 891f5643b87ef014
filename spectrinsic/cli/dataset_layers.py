"""``spectrinsic dataset``'s options for what is stored beyond the default layers: direct light,
per-light transport, per-band layers, relit variants, a camera chain."""

from __future__ import annotations

from typing import Any

__all__ = ["add_extra_layer_options"]


def add_extra_layer_options(p: Any) -> None:
    """What is rendered and stored beyond the default layers: direct light, per-light
    transport, relit variants."""
    p.add_argument(
        "--direct",
        action="store_true",
        help="also render direct light only, to record the energy ratio r per sample",
    )
    p.add_argument(
        "--store-transport",
        action="store_true",
        help="store each light's 31-band transport in every sample (transport.exr), so "
        "`spectrinsic relight` can relight it exactly; no extra render with the default "
        "single integrator (it splits every band by light), the lights one at a time "
        "with --integrator passes",
    )
    p.add_argument(
        "--spectral-layers",
        action="store_true",
        help="also write per-band intrinsic layers of the 31-band cube (spectral.exr: "
        "image, reflectance, shading, specular, residual per 10 nm band, float32), where "
        "image = reflectance * shading + specular + residual holds band by band; needs the "
        "bands31 mode (default preset); about +24 MB and +2.3 s per 256x256 sample",
    )
    p.add_argument(
        "--working-space",
        default=None,
        metavar="SPACE",
        help="RGB working space of the RGB layers: acescg (default; shading keeps its "
        "negative components: half linear sRGB's residual share, no clipping) or srgb "
        "(linear sRGB with the shading clipped at 0, the layers of before) or rec2020 "
        "(linear Rec.2020, shading unclipped); previews stay "
        "sRGB, load_sample(..., space='srgb') gives the sRGB view",
    )
    p.add_argument(
        "--relight",
        type=int,
        default=None,
        metavar="N",
        help="with --store-transport: also write N relit variants of every sample "
        "(<id>-relitK, random light spectra, seeded)",
    )
    p.add_argument(
        "--camera",
        default=None,
        metavar="NAME",
        help="run every sample through a camera (raw mosaic + DNG, noise, demosaic, white "
        "balance, colour matrix, tone curve; ground truth in the processed linear space): a "
        "preset (nikon-d5100-npl, nikon-d3) or 'camera:NAME'/'csv:PATH'; needs bands31",
    )
