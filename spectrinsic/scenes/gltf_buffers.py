"""A glTF file's buffers, buffer views and accessors checked against each other before trimesh
reads them (glTF 2.0 spec, 5.10-5.12): trimesh trusts the declared ``byteLength`` and reads a
short buffer without complaint (a ``data:`` URI 42 bytes long declared as 4,200, a 2 GB
declared buffer of a 42-byte file), so such a file is refused here, in one line naming the file
and the buffer, view or accessor, before any geometry is built.

Checked: every buffer's ``byteLength`` is an integer from 0 to :data:`MAX_BUFFER_BYTES` and its
data (a ``data:`` URI, a file inside the glTF's folder, or the GLB binary chunk) holds at least
that many bytes; every buffer view lies inside its buffer; every accessor of a view lies inside
it (``byteOffset + stride * (count - 1) + element size``).
"""

from __future__ import annotations

import base64
import binascii
from pathlib import Path
from typing import Any

from ..errors import SceneError
from .gltf_colours import gltf_document, gltf_uri_file

__all__ = ["MAX_BUFFER_BYTES", "check_gltf_buffers"]

#: Largest declared glTF buffer (bytes). The scene budget (:mod:`~spectrinsic.scenes.budget`)
#: allows 500,000 vertices and 250,000 faces: positions, normals and uv take 32 bytes per
#: vertex and indices 12 per face, 19 MB in all; 256 MiB leaves room for embedded images.
MAX_BUFFER_BYTES = 256 * 2**20

#: Bytes per component (glTF ``componentType``) and components per element (``type``).
_COMPONENT = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
_TYPE = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}


def check_gltf_buffers(path: Path) -> None:
    """Refuse *path* (``.gltf``/``.glb``) in one line if a buffer, view or accessor is not
    what it declares (module docstring). Reads buffer files' sizes, not their bytes."""
    document, binary = gltf_document(path)
    if not isinstance(document, dict):
        raise SceneError(f"{path}: expected a glTF JSON object, not {type(document).__name__}")
    sizes = [
        _buffer_size(path, i, b, binary) for i, b in enumerate(_items(path, document, "buffers"))
    ]
    views = [_view(path, i, v, sizes) for i, v in enumerate(_items(path, document, "bufferViews"))]
    for i, accessor in enumerate(_items(path, document, "accessors")):
        _check_accessor(path, i, accessor, views)


def _items(path: Path, document: dict[str, Any], key: str) -> list[dict[str, Any]]:
    items = document.get(key) or []
    if not isinstance(items, list) or not all(isinstance(x, dict) for x in items):
        raise SceneError(f"{path}: {key} must be a list of JSON objects")
    return items


def _int(path: Path, where: str, value: Any, low: int = 0, high: int = 2**63) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise SceneError(f"{path}: {where} is {value!r}; expected an integer from {low} to {high}")
    return value


def _buffer_size(path: Path, index: int, buffer: dict[str, Any], binary: bytes) -> int:
    """The declared ``byteLength`` of buffer *index*, checked against the bytes it holds."""
    where = f"buffers[{index}].byteLength"
    declared = _int(path, where, buffer.get("byteLength"), 0, MAX_BUFFER_BYTES)
    uri = buffer.get("uri")
    if uri is None:
        held = len(binary)  # the GLB binary chunk
    elif not isinstance(uri, str):
        raise SceneError(f"{path}: buffers[{index}].uri is {uri!r}; expected a string")
    elif uri.startswith("data:"):
        held = _data_uri_length(path, index, uri)
    else:
        held = gltf_uri_file(path, uri, "buffer").stat().st_size
    if held < declared:
        raise SceneError(
            f"{path}: buffers[{index}] holds {held:,} bytes but declares byteLength "
            f"{declared:,}; expected at least the declared length"
        )
    return declared


def _data_uri_length(path: Path, index: int, uri: str) -> int:
    head, _, payload = uri.partition(",")
    if not head.endswith(";base64"):
        raise SceneError(f"{path}: buffers[{index}] is a data: URI without ';base64'")
    try:
        return len(base64.b64decode(payload, validate=True))
    except (binascii.Error, ValueError):
        raise SceneError(f"{path}: buffers[{index}] is a data: URI of invalid base64") from None


def _view(path: Path, index: int, view: dict[str, Any], sizes: list[int]) -> tuple[int, int]:
    """``(byteLength, byteStride or 0)`` of buffer view *index*, inside its buffer."""
    where = f"bufferViews[{index}]"
    buffer = _int(path, f"{where}.buffer", view.get("buffer"), 0, len(sizes) - 1)
    offset = _int(path, f"{where}.byteOffset", view.get("byteOffset", 0))
    length = _int(path, f"{where}.byteLength", view.get("byteLength"), 1)
    stride = _int(path, f"{where}.byteStride", view.get("byteStride", 0), 0, 252)
    if offset + length > sizes[buffer]:
        raise SceneError(
            f"{path}: {where} spans bytes {offset:,}-{offset + length:,} of buffers[{buffer}], "
            f"which has {sizes[buffer]:,}; expected a view inside its buffer"
        )
    return length, stride


def _check_accessor(
    path: Path, index: int, accessor: dict[str, Any], views: list[tuple[int, int]]
) -> None:
    where = f"accessors[{index}]"
    if "bufferView" not in accessor:
        return  # all zeros (or sparse): nothing read from a buffer
    view = _int(path, f"{where}.bufferView", accessor["bufferView"], 0, len(views) - 1)
    component = _COMPONENT.get(accessor.get("componentType"))  # type: ignore[arg-type]
    width = _TYPE.get(accessor.get("type"))  # type: ignore[arg-type]
    if component is None or width is None:
        raise SceneError(
            f"{path}: {where} has componentType {accessor.get('componentType')!r} and type "
            f"{accessor.get('type')!r}; expected a glTF 2.0 component type and element type"
        )
    count = _int(path, f"{where}.count", accessor.get("count"), 1)
    offset = _int(path, f"{where}.byteOffset", accessor.get("byteOffset", 0))
    length, stride = views[view]
    element = component * width
    end = offset + (stride or element) * (count - 1) + element
    if end > length:
        raise SceneError(
            f"{path}: {where} reads {count:,} elements up to byte {end:,} of bufferViews[{view}], "
            f"which has {length:,}; expected an accessor inside its view"
        )
