"""glTF base colours and base-colour textures as reflectance spectra.

A glTF material's ``pbrMetallicRoughness.baseColorFactor`` is a linear-sRGB colour (glTF 2.0
spec, section 3.9.2) and its ``baseColorTexture`` an sRGB-encoded image that the factor
multiplies (section 3.9.2, 3.8.4). :func:`gltf_colours` reads both for every named material:
a factor alone becomes the registry name ``rgb:R,G,B`` (:mod:`spectrinsic.spectra.user_spectra`:
Mallett & Yuksel 2019), a texture an :class:`~spectrinsic.scenes.image_textures.ImageTexture`
(decoded, times the factor, with the sampler's wrap mode and filter), which the mesh reader maps
by the primitive's own ``TEXCOORD_0``. Alpha is read only under an ``alphaMode`` of ``MASK`` or
``BLEND`` (as an opacity mask, :mod:`~spectrinsic.scenes.gltf_maps`). A factor outside
[0, 1] is refused when the scene is validated, not clipped. Materials with neither get nothing
(glTF's default white is not assumed): such a material still needs the map or a default.

Images are read from the file's own binary chunk (``.glb``), a ``data:`` URI or a file beside
the ``.gltf`` (inside its folder; a path escaping it is refused).
"""

from __future__ import annotations

import base64
import json
import struct
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ..errors import SceneError, SpectrinsicWarning
from .image_textures import AssetColour, Filter, ImageTexture, Wrap, image_texture_from_bytes

__all__ = [
    "GLTF_SUFFIXES",
    "gltf_colours",
    "gltf_document",
    "gltf_uri_file",
    "gltf_image",
    "gltf_image_bytes",
    "named_materials",
]

#: File suffixes read as glTF (lower case): JSON and binary.
GLTF_SUFFIXES = (".gltf", ".glb")

#: glTF sampler codes (spec 5.26): wrapS/wrapT and magFilter.
_WRAP = {10497: "repeat", 33071: "clamp", 33648: "mirror"}
_NEAREST = 9728


def gltf_document(path: Path) -> tuple[dict[str, Any], bytes]:
    """The glTF JSON and, for ``.glb``, its binary chunk (``b""`` otherwise)."""
    data = path.read_bytes()
    try:
        if path.suffix.lower() == ".glb":
            length = struct.unpack("<I", data[12:16])[0]
            document = json.loads(data[20 : 20 + length])
            rest = data[20 + length :]
            binary = rest[8 : 8 + struct.unpack("<I", rest[:4])[0]] if len(rest) >= 8 else b""
            return document, binary
        return json.loads(data), b""
    except (ValueError, struct.error) as exc:
        raise SceneError(f"{path}: cannot read its glTF JSON ({exc})") from None


def named_materials(document: dict[str, Any]) -> Iterator[tuple[str, dict[str, Any]]]:
    """``(name, material)`` of every material of a glTF *document* that is a JSON object with
    a string ``name`` (what the readers of colours, maps and glass key their results by);
    others are skipped."""
    for material in document.get("materials") or []:
        if isinstance(material, dict) and isinstance(material.get("name"), str):
            yield material["name"], material


def gltf_uri_file(path: Path, uri: str, what: str) -> Path:
    """The file a glTF's relative *uri* (of an image or buffer, *what*) names, which must lie
    inside *path*'s folder (no ``../`` or absolute escapes, links resolved first)."""
    base = path.parent.resolve()
    full = (base / uri).resolve()
    if not full.is_relative_to(base) or not full.is_file():
        raise SceneError(f"{path}: {what} {uri!r} is not a file inside {base}")
    return full


def _uri_bytes(path: Path, uri: str) -> bytes:
    """The bytes a glTF *uri* names: a ``data:`` URI or a file inside *path*'s folder."""
    if uri.startswith("data:"):
        return base64.b64decode(uri.split(",", 1)[-1])
    return gltf_uri_file(path, uri, "image or buffer").read_bytes()


def _image_bytes(path: Path, doc: dict[str, Any], binary: bytes, index: int) -> bytes:
    image = (doc.get("images") or [])[index]
    if "uri" in image:
        return _uri_bytes(path, str(image["uri"]))
    view = doc["bufferViews"][int(image["bufferView"])]
    buffer = doc["buffers"][int(view.get("buffer", 0))]
    data = _uri_bytes(path, str(buffer["uri"])) if "uri" in buffer else binary
    offset = int(view.get("byteOffset", 0))
    return data[offset : offset + int(view["byteLength"])]


def gltf_image_bytes(
    path: Path, doc: dict[str, Any], binary: bytes, ref: Any, key: str = "baseColorTexture"
) -> tuple[bytes, int, Wrap, Filter]:
    """The image file's bytes, image index, wrap mode and filter of a texture reference *ref*
    (a material's *key*, such as ``normalTexture``)."""
    try:
        texture = doc["textures"][int(ref["index"])]
        index = int(texture["source"])
        data = _image_bytes(path, doc, binary, index)
        sampler = (
            (doc.get("samplers") or [{}])[int(texture["sampler"])] if "sampler" in texture else {}
        )
    except SceneError:
        raise
    except (KeyError, IndexError, TypeError, ValueError) as exc:
        raise SceneError(f"{path}: {key} {ref!r} names nothing readable ({exc!r})") from None
    if ref.get("extensions"):  # KHR_texture_transform and the like would move the texels
        raise SceneError(f"{path}: {key} extensions {sorted(ref['extensions'])} are not supported")
    if int(ref.get("texCoord", 0)) != 0:
        raise SceneError(f"{path}: {key} uses TEXCOORD_{ref['texCoord']}; expected 0")
    wraps = {_WRAP.get(int(sampler.get(k, 10497)), "repeat") for k in ("wrapS", "wrapT")}
    if len(wraps) > 1:
        raise SceneError(
            f"{path}: sampler wraps S and T differently ({sorted(wraps)}); expected one mode"
        )
    wrap: Wrap = wraps.pop()  # type: ignore[assignment]
    filt: Filter = "nearest" if sampler.get("magFilter") == _NEAREST else "bilinear"
    return data, index, wrap, filt


def gltf_image(
    path: Path,
    doc: dict[str, Any],
    binary: bytes,
    ref: Any,
    factor: Any,
    *,
    key: str = "baseColorTexture",
    srgb: bool = True,
) -> ImageTexture:
    """The ImageTexture of a texture reference *ref* (a material's *key*), times *factor*;
    sRGB-decoded if *srgb* (a base colour), else raw (data: normals)."""
    data, index, wrap, filt = gltf_image_bytes(path, doc, binary, ref, key)
    return image_texture_from_bytes(
        data,
        source=f"{path.name}#images/{index}",
        srgb=srgb,
        wrap=wrap,
        filter=filt,
        factor=tuple(float(c) for c in factor[:3]),  # type: ignore[arg-type]
    )


def gltf_colours(path: str | Path) -> dict[str, AssetColour]:
    """``{material name: AssetColour}`` for every named material of the ``.gltf``/``.glb``
    file at *path* with a ``baseColorFactor`` or a ``baseColorTexture`` (module docstring);
    ``{}`` for other files."""
    path = Path(path)
    if path.suffix.lower() not in GLTF_SUFFIXES:
        return {}
    doc, binary = gltf_document(path)
    out = {}
    for name, material in named_materials(doc):
        pbr = material.get("pbrMetallicRoughness") or {}
        factor = pbr.get("baseColorFactor")
        stated = isinstance(factor, list) and len(factor) == 4
        if "baseColorTexture" in pbr:
            with warnings.catch_warnings():  # alpha is read where alphaMode uses it (gltf_maps)
                if material.get("alphaMode", "OPAQUE") != "OPAQUE":
                    warnings.filterwarnings("ignore", ".*alpha below 1", SpectrinsicWarning)
                image = gltf_image(
                    path, doc, binary, pbr["baseColorTexture"], factor if stated else [1, 1, 1]
                )
            out[name] = AssetColour(image=image)
        elif isinstance(factor, list) and len(factor) == 4:
            rgb = "rgb:" + ",".join(f"{float(c):.9g}" for c in factor[:3])
            out[name] = AssetColour(spectrum=rgb)
    return out
