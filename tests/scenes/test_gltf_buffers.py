"""glTF buffers, views and accessors that do not hold what they declare are refused in one line
before trimesh reads them (task r5-probe: trimesh read a 42-byte buffer declared as 4,200 or
2 GB bytes without complaint, and the scene rendered)."""

from __future__ import annotations

import base64
import json
import struct

import pytest

from spectrinsic.errors import SceneError
from spectrinsic.scenes.gltf_buffers import MAX_BUFFER_BYTES, check_gltf_buffers

#: One triangle: 3 float32 positions (36 bytes) and 3 uint16 indices (6 bytes).
DATA = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<3H", 0, 1, 2)


def _doc(uri: str | None = None, length: int = len(DATA), count: int = 3, view_offset: int = 36):
    return {
        "asset": {"version": "2.0"},
        "buffers": [
            {"uri": uri or "data:;base64," + base64.b64encode(DATA).decode(), "byteLength": length}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": view_offset, "byteLength": 6},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
    }


def _write(tmp_path, doc) -> object:
    (tmp_path / "b.bin").write_bytes(DATA)
    path = tmp_path / "s.gltf"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("uri", [None, "b.bin"])
def test_a_consistent_file_passes(tmp_path, uri):
    check_gltf_buffers(_write(tmp_path, _doc(uri)))


@pytest.mark.parametrize(
    "doc, needle",
    [
        (_doc(length=4200), "holds 42 bytes but declares byteLength 4,200"),
        (_doc("b.bin", length=2_000_000_000), f"from 0 to {MAX_BUFFER_BYTES}"),
        (_doc("b.bin", length=43), "holds 42 bytes"),
        (_doc("data:;base64,@@@@"), "invalid base64"),
        (_doc("../b.bin"), "not a file inside"),
        (_doc(view_offset=4000), "bufferViews[1] spans bytes 4,000-4,006"),
        (_doc(count=300_000), "accessors[0] reads 300,000 elements"),
        (_doc(count=4), "accessors[0] reads 4 elements up to byte 48"),
    ],
)
def test_what_does_not_hold_what_it_declares_is_refused(tmp_path, doc, needle):
    with pytest.raises(SceneError, match="s.gltf") as info:
        check_gltf_buffers(_write(tmp_path, doc))
    assert needle in str(info.value) and "\n" not in str(info.value)
