"""glTF base colours as reflectance spectra.

A glTF material's ``pbrMetallicRoughness.baseColorFactor`` is a linear-sRGB colour (glTF 2.0
spec, section 3.9.2); :func:`gltf_base_colours` turns each one the file states into the
registry name ``rgb:R,G,B`` (:mod:`spectrinsic.spectra.user_spectra`: Mallett & Yuksel 2019),
so a coloured asset renders in its colours without a material map when asked for
(``colours_from_asset=True``, ``--colours-from-asset``; without it an unmapped material is an
error, :mod:`spectrinsic.scenes.meshes`). Alpha is ignored (surfaces
are opaque). A factor outside [0, 1] is refused when the scene is validated, not clipped.
Materials without an explicit factor get none (glTF's default white is not assumed), and
``baseColorTexture`` images are not read: such materials still need the map or a default.

Why textures are not read (yet): the uplift is linear in linear RGB, so a texel's reflectance
is exactly the trilinear mix of the 8 spectra ``rgb:`` of the RGB cube's corners (weights
``Π x_i or 1 - x_i``, non-negative, summing to 1), which is the convex per-texel mix the
textured-material route (:mod:`spectrinsic.scenes.textures`) keeps exact. Two limits of that
route stand in the way: a texture has at most ``BASIS_MAX`` = 4 basis spectra (an arbitrary
image needs all 8 corners; the 3 primaries alone are not convex, their weights sum to
R + G + B), and texels are placed by its one box projection (``box_uv``), not by the asset's
own ``TEXCOORD_0``, so the image would land in the wrong places. Raising ``BASIS_MAX`` to 8 and
carrying per-vertex UVs in :class:`~spectrinsic.scenes.textures.Texture` (scene format and
renderer lookup) would make sRGB-decoded ``baseColorTexture`` images exact.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import Any

from ..errors import SceneError

__all__ = ["gltf_base_colours"]


def _document(path: Path) -> dict[str, Any]:
    data = path.read_bytes()
    try:
        if path.suffix.lower() == ".glb":
            length = struct.unpack("<I", data[12:16])[0]
            return json.loads(data[20 : 20 + length])
        return json.loads(data)
    except (ValueError, struct.error) as exc:
        raise SceneError(f"{path}: cannot read its glTF JSON ({exc})") from None


def gltf_base_colours(path: str | Path) -> dict[str, str]:
    """``{material name: "rgb:R,G,B"}`` for every named material of the ``.gltf``/``.glb``
    file at *path* with a ``baseColorFactor`` (module docstring); ``{}`` for other files."""
    path = Path(path)
    if path.suffix.lower() not in (".gltf", ".glb"):
        return {}
    out = {}
    for material in _document(path).get("materials") or []:
        if not isinstance(material, dict) or not isinstance(material.get("name"), str):
            continue
        factor = (material.get("pbrMetallicRoughness") or {}).get("baseColorFactor")
        if isinstance(factor, list) and len(factor) == 4:
            out[material["name"]] = "rgb:" + ",".join(f"{float(c):.9g}" for c in factor[:3])
    return out
