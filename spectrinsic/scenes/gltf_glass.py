"""glTF glass: ``KHR_materials_transmission`` as clear glass materials.

A glTF material whose ``KHR_materials_transmission.transmissionFactor`` is 1 is clear glass
(:class:`~spectrinsic.scenes.model.Material` kind ``dielectric`` or ``thindielectric``): of
index ``KHR_materials_ior.ior`` (glTF's default 1.5) and GGX α = roughness² (glTF's
``roughnessFactor``, default 1, as the metallic-roughness model defines it). Without
``KHR_materials_volume`` (or with ``thicknessFactor`` 0) a glTF material is thin-walled
(extension specification), so it becomes a ``thindielectric``, which is smooth only: a rough
thin-walled glass is refused. A ``KHR_materials_volume`` with a thickness makes a solid
``dielectric`` (its attenuation must be absent: no tint).

What has no exact ground truth is refused in one line naming the material: a factor strictly
between 0 and 1 (a mix of glass and the diffuse base), a ``transmissionTexture``, a tinted base
colour (glTF multiplies the transmitted light by it), or a volume attenuation. A factor of 0 (or
no extension) leaves the material to the metallic-roughness reading.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import SceneError
from .gltf_colours import GLTF_SUFFIXES, gltf_document, named_materials

__all__ = ["TRANSMISSION", "gltf_glass"]

#: The glTF extension read.
TRANSMISSION = "KHR_materials_transmission"


def _number(value: Any, default: float) -> float:
    return (
        float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else default
    )


def _glass(name: str, material: dict[str, Any], where: str) -> dict[str, Any] | None:
    """Gloss fields of one glTF *material*, or ``None`` where it does not transmit."""
    ext = material.get("extensions") or {}
    transmission = ext.get(TRANSMISSION)
    if not isinstance(transmission, dict):
        return None
    factor = _number(transmission.get("transmissionFactor"), 0.0)
    what = f"{where}: material {name!r}: {TRANSMISSION}"
    if "transmissionTexture" in transmission:
        raise SceneError(f"{what} has a transmissionTexture; only a uniform factor 0 or 1 is exact")
    if factor == 0.0:
        return None
    if factor != 1.0:
        raise SceneError(
            f"{what} transmissionFactor {factor:g}; only 1 (clear glass) or 0 has exact ground truth"
        )
    pbr = material.get("pbrMetallicRoughness") or {}
    tint = pbr.get("baseColorFactor", [1, 1, 1, 1])
    if "baseColorTexture" in pbr or [_number(c, -1) for c in tint[:3]] != [1.0, 1.0, 1.0]:
        raise SceneError(f"{what} with a tinted base colour; only clear glass (white) is exact")
    volume = ext.get("KHR_materials_volume") or {}
    if "attenuationColor" in volume or "attenuationDistance" in volume:
        raise SceneError(f"{what} with a volume attenuation; only clear glass is exact")
    alpha = min(max(_number(pbr.get("roughnessFactor"), 1.0), 0.0), 1.0) ** 2
    ior = _number((ext.get("KHR_materials_ior") or {}).get("ior"), 1.5)
    if _number(volume.get("thicknessFactor"), 0.0) > 0.0:
        return {"kind": "dielectric", "ior": ior, "roughness": alpha}
    if alpha > 0.0:
        raise SceneError(
            f"{what} thin-walled (no KHR_materials_volume) with roughness {alpha**0.5:g}; "
            "a thin pane is smooth only (add a volume thickness for rough solid glass)"
        )
    return {"kind": "thindielectric", "ior": ior}


def gltf_glass(path: str | Path) -> dict[str, dict[str, Any]]:
    """``{material name: gloss fields}`` of the named glass materials of the ``.gltf``/``.glb``
    file at *path* (module docstring); ``{}`` for other files."""
    path = Path(path)
    if path.suffix.lower() not in GLTF_SUFFIXES:
        return {}
    doc, _ = gltf_document(path)
    out = {}
    for name, material in named_materials(doc):
        glass = _glass(name, material, str(path))
        if glass is not None:
            out[name] = glass
    return out
