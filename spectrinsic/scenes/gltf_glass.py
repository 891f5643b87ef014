"""glTF glass: ``KHR_materials_transmission`` as glass materials, clear or tinted.

A glTF material whose ``KHR_materials_transmission.transmissionFactor`` is 1 is glass
(:class:`~spectrinsic.scenes.model.Material` kind ``dielectric`` or ``thindielectric``): of
index ``KHR_materials_ior.ior`` (glTF's default 1.5) and GGX α = roughness² (glTF's
``roughnessFactor``, default 1, as the metallic-roughness model defines it). Without
``KHR_materials_volume`` (or with ``thicknessFactor`` 0) a glTF material is thin-walled
(extension specification), so it becomes a ``thindielectric``, which is smooth only: a rough
thin-walled glass is refused. A ``KHR_materials_volume`` with a thickness makes a solid
``dielectric``. glTF tints the transmitted light (not the reflected) by the base colour: a
``baseColorFactor`` other than white becomes the material's ``transmittance``, ``rgb:R,G,B``
of its linear RGB (Mallett–Yuksel upsampled, as every glTF colour), applied at each crossing.

What has no exact ground truth is refused in one line naming the material: a factor strictly
between 0 and 1 (a mix of glass and the diffuse base), a ``transmissionTexture``, a textured
tint (``baseColorTexture``), or a volume attenuation (``attenuationColor`` /
``attenuationDistance``: absorption along the path inside, Beer–Lambert, which the renderer
does not trace), and a ``KHR_materials_specular`` other than its defaults on glass: its
``specularColorFactor`` scales the Schlick F0 but not F90 (the grazing reflection stays white)
and changes the transmission with it, so it is no multiplicative reflection tint
(Mitsuba's ``specular_reflectance``). A factor of 0 (or no extension) leaves the material to
the metallic-roughness reading.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import SceneError
from .gltf_colours import GLTF_SUFFIXES, gltf_document, named_materials

__all__ = ["TRANSMISSION", "gltf_glass"]

#: The glTF extension read.
TRANSMISSION = "KHR_materials_transmission"
#: The glTF extension refused on glass unless at its defaults (module docstring).
SPECULAR = "KHR_materials_specular"


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
            f"{what} transmissionFactor {factor:g}; only 1 (glass) or 0 has exact ground truth"
        )
    _plain_specular(ext.get(SPECULAR), what)
    pbr = material.get("pbrMetallicRoughness") or {}
    tint = _tint(pbr, what)
    volume = ext.get("KHR_materials_volume") or {}
    if "attenuationColor" in volume or "attenuationDistance" in volume:
        raise SceneError(
            f"{what} with a volume attenuation (absorption along the path inside); only a "
            "surface tint, the baseColorFactor, is exact"
        )
    alpha = min(max(_number(pbr.get("roughnessFactor"), 1.0), 0.0), 1.0) ** 2
    ior = _number((ext.get("KHR_materials_ior") or {}).get("ior"), 1.5)
    tinted = {"transmittance": tint} if tint else {}
    if _number(volume.get("thicknessFactor"), 0.0) > 0.0:
        return {"kind": "dielectric", "ior": ior, "roughness": alpha} | tinted
    if alpha > 0.0:
        raise SceneError(
            f"{what} thin-walled (no KHR_materials_volume) with roughness {alpha**0.5:g}; "
            "a thin pane is smooth only (add a volume thickness for rough solid glass)"
        )
    return {"kind": "thindielectric", "ior": ior} | tinted


def _plain_specular(specular: Any, what: str) -> None:
    """Refuse a ``KHR_materials_specular`` *specular* that is not at its defaults (factor 1,
    white colour, no textures; module docstring)."""
    if specular is None:
        return
    textured = isinstance(specular, dict) and bool(
        {"specularTexture", "specularColorTexture"} & set(specular)
    )
    plain = isinstance(specular, dict) and not textured
    plain = plain and specular.get("specularFactor", 1) == 1
    plain = plain and specular.get("specularColorFactor", [1, 1, 1]) == [1, 1, 1]
    if not plain:
        raise SceneError(
            f"{what} with {SPECULAR} {specular!r}; its Schlick F0 scale is no exact reflection "
            "tint (only the defaults, factor 1 and white, are read)"
        )


def _tint(pbr: dict[str, Any], what: str) -> str:
    """The glass's transmittance from its ``baseColorFactor``: ``rgb:R,G,B``, or ``""`` for
    white (clear glass); a ``baseColorTexture`` or a factor that is not 3-4 numbers in [0, 1]
    is refused."""
    if "baseColorTexture" in pbr:
        raise SceneError(
            f"{what} with a baseColorTexture: a textured tint has no exact ground truth"
        )
    factor = pbr.get("baseColorFactor", [1, 1, 1, 1])
    rgb = [_number(c, -1.0) for c in factor[:3]] if isinstance(factor, list) else []
    if len(rgb) != 3 or not all(0.0 <= c <= 1.0 for c in rgb):
        raise SceneError(f"{what}: baseColorFactor {factor!r}; expected 3 or 4 numbers in [0, 1]")
    return "" if rgb == [1.0, 1.0, 1.0] else "rgb:" + ",".join(f"{c:.9g}" for c in rgb)


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
