"""The layer options of ``spectrinsic dataset`` and ``spectrinsic render --ground-truth``: what
is stored beyond the default layers (a camera chain, per-band layers, the RGB working space,
per-light transport). Both verbs add them through :func:`add_layer_options` and read them
through :func:`layer_changes`, so the two cannot drift apart; ``dataset`` adds direct light and
relit variants (:func:`add_extra_layer_options`)."""

from __future__ import annotations

import argparse
from typing import Any

__all__ = [
    "LAYER_OPTIONS",
    "add_layer_options",
    "add_extra_layer_options",
    "given_layer_options",
    "layer_changes",
]

#: The shared layer options: option -> (namespace dest, config key, switch?).
LAYER_OPTIONS: dict[str, tuple[str, str, bool]] = {
    "--camera": ("camera", "camera", False),
    "--spectral-layers": ("spectral_layers", "spectral_layers", True),
    "--working-space": ("working_space", "working_space", False),
    "--store-transport": ("store_transport", "store_transport", True),
}


def add_layer_options(p: Any) -> None:
    """The layer options both ``dataset`` and ``render --ground-truth`` take."""
    p.add_argument(
        "--camera",
        default=None,
        metavar="NAME",
        help="run every sample through a camera (raw mosaic + DNG, noise, demosaic, white "
        "balance, colour matrix, tone curve; ground truth in the processed linear space): a "
        "preset (`spectrinsic list cameras`) or 'camera:NAME'/'csv:PATH'; needs bands31",
    )
    p.add_argument(
        "--spectral-layers",
        action="store_true",
        help="also write per-band intrinsic layers of the 31-band cube (spectral.exr: "
        "image, reflectance, shading, specular, residual per 10 nm band, float32), where "
        "image = reflectance * shading + specular + residual holds band by band; needs the "
        "bands31 mode (default preset); about +13.5 MB and +2.3 s per 256x256 sample",
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
        "--store-transport",
        action="store_true",
        help="store each light's 31-band transport in every sample (transport.exr), so "
        "`spectrinsic relight` can relight it exactly; no extra render with the default "
        "single integrator (it splits every band by light), the lights one at a time "
        "with --integrator passes",
    )


def add_extra_layer_options(p: Any) -> None:
    """``dataset``'s layer options: the shared ones, direct light and relit variants."""
    p.add_argument(
        "--direct",
        action="store_true",
        help="also render direct light only, to record the energy ratio r per sample",
    )
    add_layer_options(p)
    p.add_argument(
        "--relight",
        type=int,
        default=None,
        metavar="N",
        help="with --store-transport: also write N relit variants of every sample "
        "(<id>-relitK, random light spectra, seeded)",
    )


def given_layer_options(args: argparse.Namespace) -> list[str]:
    """The shared layer options given on the command line, by their option names."""
    given = []
    for option, (dest, _key, switch) in LAYER_OPTIONS.items():
        value = getattr(args, dest, None)
        if (switch and value) or (not switch and value is not None):
            given.append(option)
    return given


def layer_changes(args: argparse.Namespace) -> dict[str, object]:
    """The config changes (``DatasetConfig.with_options`` keys) the shared options ask for."""
    changes: dict[str, object] = {}
    for option in given_layer_options(args):
        dest, key, switch = LAYER_OPTIONS[option]
        changes[key] = True if switch else getattr(args, dest)
    return changes
