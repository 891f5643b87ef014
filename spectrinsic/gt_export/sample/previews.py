"""PNG previews of ground-truth layers: which maker draws each layer, and how its pixels decode.

Previews are for looking only (the data are the EXR files). Each maker returns the 8-bit image
and its encoding, which ``meta.json["layers"][key]["preview_encoding"]`` records so a viewer can
turn a pixel back into the value it stands for.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ...spectra.working_space import WorkingSpace
from ..formats import png
from ..layers import Layer
from ..layers.gloss import SPECULAR
from . import PREVIEW_DIR
from .working_view import srgb_layer, view_kind

__all__ = ["Preview", "preview_maker", "preview_path", "shown_layers"]


#: A preview and how its pixels encode the layer: ``{"kind": "srgb", "scale": k}`` (PNG =
#: sRGB-encoded ``clip(value × k)``, so ``value = decode(PNG) / k`` below the clip),
#: ``{"kind": "colormap", "cmap", "vmin", "vmax"}`` (false colour of a scalar) or
#: ``{"kind": "categorical"}`` (ids, normals, mask).
Preview = tuple[np.ndarray, dict[str, Any]]

#: Layers that share one exposure per sample, so brightness differences between them are real:
#: every image mode and camera image uses ``image``'s, every shading ``shading``'s.
_EXPOSURE_OF = (("image", "image"), ("shading", "shading"), (SPECULAR, "image"))


def _srgb(data: np.ndarray, scale: float) -> Preview:
    return png.encode_srgb8(data, scale), {"kind": "srgb", "scale": float(scale)}


def _colour_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    base = next((b for prefix, b in _EXPOSURE_OF if layer.name.startswith(prefix)), layer.name)
    return _srgb(layer.data, png.exposure(layers.get(base, layer).data))


def _reflectance_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _srgb(layer.data, 1.0)  # absolute scale: the perfect white is 1


def _illuminant_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    # unit luminance: D65 light is (1, 1, 1); a scale of 1/2 keeps saturated light unclipped
    return _srgb(layer.data, 0.5)


def _grey_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _srgb(np.repeat(layer.data[..., None], 3, axis=-1), png.exposure(layer.data))


def _colormap(
    values: np.ndarray,
    vmin: float,
    vmax: float,
    cmap: str = "magma",
    mask: np.ndarray | None = None,
) -> Preview:
    return (
        png.false_colour(values, mask=mask, cmap=cmap, vmin=vmin, vmax=vmax),
        {"kind": "colormap", "cmap": cmap, "vmin": float(vmin), "vmax": float(vmax)},
    )


def _error_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _colormap(layer.data, 0.0, 0.1)


def _residual_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    """Magnitude of the residual relative to the image: 0 (black) to 10 % (bright)."""
    base = layers.get(layer.name.replace("residual", "image", 1).replace("image_raw", "image"))
    norm = np.linalg.norm(base.data, axis=-1) if base is not None else np.ones(layer.data.shape[:2])
    rel = np.divide(
        np.linalg.norm(layer.data, axis=-1), norm, out=np.zeros(norm.shape), where=norm > 0
    )
    preview, encoding = _colormap(rel, 0.0, 0.1)
    return preview, {**encoding, "of": "‖residual‖ / ‖image‖"}


def _unit_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    """Maps in [0, 1] (``non_diffuse``, ``metallic``, ``roughness``)."""
    return _colormap(layer.data, 0.0, 1.0, cmap="viridis")


def _noise_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _colormap(layer.data, 0.0, 0.2)


def _mask_of(layers: Mapping[str, Layer]) -> np.ndarray | None:
    return layers["mask"].data > 0.5 if "mask" in layers else None


def _depth_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    mask = _mask_of(layers)
    valid = layer.data[mask] if mask is not None else layer.data.ravel()
    lo, hi = (
        (float(np.percentile(valid, 1)), float(np.percentile(valid, 99)))
        if valid.size
        else (0.0, 1.0)
    )
    return _colormap(layer.data, lo, hi, cmap="viridis", mask=mask)


def _categorical(rgb8: np.ndarray) -> Preview:
    return rgb8, {"kind": "categorical"}


def _normals_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _categorical(png.normals_preview(layer.data, _mask_of(layers)))


def _ids_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _categorical(png.id_colours(layer.data))


def _mask_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _categorical(np.repeat((layer.data > 0.5).astype(np.uint8)[..., None] * 255, 3, axis=-1))


def _processed_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    """A camera chain's processed codes, as they are (16-bit codes to their top 8 bits)."""
    top = 255.0 if layer.data.max() <= 255 else 65535.0
    return _categorical(np.rint(layer.data / top * 255).astype(np.uint8))


def _raw_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    """A raw Bayer mosaic in grey, its 99th percentile white."""
    return _colormap(
        layer.data, float(layer.data.min()), float(np.percentile(layer.data, 99)), cmap="gray"
    )


#: (layer-name prefix, preview maker); the first matching prefix wins; no match, no preview.
_PREVIEWS: tuple[tuple[str, Callable[[Layer, Mapping[str, Layer]], Preview]], ...] = (
    ("image", _colour_preview),
    ("shading_grey", _grey_preview),
    ("shading", _colour_preview),
    ("reflectance", _reflectance_preview),
    ("illuminant", _illuminant_preview),
    ("error_", _error_preview),
    ("residual", _residual_preview),
    (SPECULAR, _colour_preview),
    ("non_diffuse", _unit_preview),
    ("metallic", _unit_preview),
    ("transmissive", _unit_preview),
    ("roughness", _unit_preview),
    ("noise_", _noise_preview),
    ("depth", _depth_preview),
    ("normals", _normals_preview),
    ("material_id", _ids_preview),
    ("object_id", _ids_preview),
    ("semantic", _ids_preview),
    ("mask", _mask_preview),
    ("processed_sensor", _processed_preview),
    ("raw_sensor", _raw_preview),
)


def preview_maker(layer: Layer) -> Callable[[Layer, Mapping[str, Layer]], Preview] | None:
    """The maker of *layer*'s preview (first matching prefix of :data:`_PREVIEWS`), or ``None``
    (also for band layers, ``*_bands``: their sRGB views are the RGB layers' previews)."""
    if layer.data.ndim == 3 and layer.data.shape[-1] not in (1, 3):
        return None
    return next((f for prefix, f in _PREVIEWS if layer.name.startswith(prefix)), None)


def preview_path(layer: Layer) -> str:
    """The preview's path inside the sample folder: ``previews/<layer>.png``, camera views
    ``previews/<layer>--<camera slug>.png``."""
    base, _, camera = layer.name.partition("/")
    name = f"{base}--{layer.group.removeprefix('camera-')}.png" if camera else f"{base}.png"
    return f"{PREVIEW_DIR}/{name}"


def shown_layers(layers: Mapping[str, Layer], space: WorkingSpace) -> dict[str, Layer]:
    """*layers* with the working-space RGB ones in linear sRGB, as previews show them
    (:mod:`~spectrinsic.gt_export.sample.working_view`; residuals by the matrix alone, enough for
    their magnitude maps); the same layers for an sRGB sample."""
    if space.name == "srgb":
        return dict(layers)
    out = dict(layers)
    for name, layer in layers.items():
        if layer.data.ndim != 3 or layer.data.shape[-1] != 3:
            continue
        data = srgb_layer(name, layer.data, space)
        if data is None and view_kind(name) == "recomputed":
            data = space.srgb(layer.data)
        if data is not None:
            out[name] = dataclasses.replace(layer, data=data.astype(np.float32))
    return out
