"""The sRGB view of a sample's RGB layers, whatever its working space
(:mod:`spectrinsic.spectra.working_space`, ``meta.json["working_space"]``).

With ``T`` the space's ``rgb_to_srgb`` matrix, ``w`` its D65 white and ``w_s`` sRGB's:

* colours (``image``, ``image_<mode>``, ``image_denoised``, ``reflectance``, ``specular``):
  ``T v`` — exact, the same values a linear-sRGB sample holds (the reflectance too: both are
  the surface's XYZ under D65 through a matrix);
* light (``shading``, ``shading_raw``, ``illuminant``): ``T (v ∘ w) / w_s``, the same light
  relative to sRGB's white (D65 stays ``(1, 1, 1)``); not clipped, so out-of-sRGB-gamut light
  keeps its negative components;
* ``residual``/``residual_raw`` recomputed from the viewed layers of their identity
  (``meta.json["identities"]``), so ``image = reflectance ∘ shading [+ specular] + residual``
  holds in the view too; ``shading_ratio`` recomputed as ``image / reflectance``.

Camera, sensor and band layers and scalars are not RGB of the working space and are left as
they are. PNG previews are drawn from this view (clipped to [0, 1] for display), and
``load_sample(..., space="srgb")`` returns it; ``spectrinsic evaluate`` scores in it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ...spectra.working_space import WorkingSpace, working_space
from ..layers.gloss import SPECULAR
from ..layers.records import REFLECTANCE_FLOOR

__all__ = ["space_of", "view_kind", "srgb_layer", "srgb_view"]

_COLOURS = ("image", "image_denoised", "reflectance", SPECULAR)
_LIGHTS = ("shading", "shading_raw", "illuminant")
_RECOMPUTED = ("residual", "residual_raw", "shading_ratio")


def space_of(meta: Any) -> WorkingSpace:
    """The working space a parsed ``meta.json`` records (``srgb`` for samples written before
    it was recorded); :class:`~spectrinsic.errors.WorkingSpaceError` for an unknown name."""
    record = meta.get("working_space") if isinstance(meta, Mapping) else None
    name = record.get("name", "srgb") if isinstance(record, Mapping) else "srgb"
    return working_space(name, "meta.json working_space")


def view_kind(name: str) -> str | None:
    """``"colour"``, ``"light"``, ``"recomputed"`` or ``None`` (not a working-space layer).

    >>> view_kind("image_rgb3"), view_kind("shading"), view_kind("image_camera/Nikon")
    ('colour', 'light', None)
    """
    if "/" in name or name.endswith(("_bands", "_bands_raw")):
        return None
    if name in _COLOURS or (name.startswith("image_") and name.removeprefix("image_").isalnum()):
        return "colour"
    if name in _LIGHTS:
        return "light"
    return "recomputed" if name in _RECOMPUTED else None


def srgb_layer(name: str, data: np.ndarray, space: WorkingSpace) -> np.ndarray | None:
    """The sRGB view of one colour or light layer (float64), or ``None`` for other layers
    (the residuals and ratio need their identity: :func:`srgb_view`)."""
    kind = view_kind(name)
    if kind == "colour":
        return space.srgb(data)
    if kind == "light":
        return space.srgb(np.asarray(data, np.float64) * space.white) / working_space("srgb").white
    return None


def _recompute(out: dict[str, Any], identities: Any) -> None:
    for ident in identities if isinstance(identities, list) else []:
        if not isinstance(ident, Mapping) or view_kind(str(ident.get("residual"))) is None:
            continue
        if not all(ident.get(k) in out for k in ("image", "reflectance", "shading")):
            continue
        rest = out[ident["image"]] - out[ident["reflectance"]] * out[ident["shading"]]
        if ident.get(SPECULAR) in out:
            rest = rest - out[ident[SPECULAR]]
        out[ident["residual"]] = rest.astype(np.float32)
    if "shading_ratio" in out and "image" in out and "reflectance" in out:
        refl = np.asarray(out["reflectance"], np.float64)
        ok = np.abs(refl) > REFLECTANCE_FLOOR
        ratio = np.divide(out["image"], refl, out=np.zeros(refl.shape), where=ok)
        out["shading_ratio"] = ratio.astype(np.float32)


def srgb_view(sample: Mapping[str, Any], meta: Any) -> dict[str, Any]:
    """A copy of a loaded sample dict with its working-space RGB layers in linear sRGB
    (module notes; float32 like the stored layers) and its ``meta["working_space"]`` the
    sRGB record (with ``"view_of"``: the stored space), so a second call changes nothing; a
    copy of the sample itself if it is sRGB."""
    space = space_of(meta)
    if space.name == "srgb":
        return dict(sample)
    out = dict(sample)
    if isinstance(sample.get("meta"), Mapping):
        # the view keeps out-of-gamut light's negative components: its shading is not clipped
        record = working_space("srgb").record() | {"view_of": space.name, "shading_clipped": False}
        out["meta"] = {**sample["meta"], "working_space": record}
    for name, value in sample.items():
        if isinstance(value, np.ndarray) and value.ndim == 3 and value.shape[-1] == 3:
            viewed = srgb_layer(name, value, space)
            if viewed is not None:
                out[name] = viewed.astype(np.float32)
    _recompute(out, meta.get("identities") if isinstance(meta, Mapping) else None)
    return out
