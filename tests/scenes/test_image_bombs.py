"""Image files that are not images, or declare a huge size (a decompression bomb), are refused
in one line naming the texture, by every image reader of scene files (task r5-probe: a glTF
base colour PNG declaring 100000x100000 texels gave PIL's DecompressionBombError traceback)."""

from __future__ import annotations

import struct
import zlib

import pytest

from spectrinsic.errors import SceneError
from spectrinsic.scenes.image_textures import IMAGE_TEXELS_MAX, image_texture_from_bytes
from spectrinsic.scenes.surface_maps import alpha_values


def png_declaring(width: int, height: int) -> bytes:
    """A PNG whose header declares *width* x *height* RGB texels and holds no pixel data."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        crc = struct.pack(">I", zlib.crc32(kind + data))
        return struct.pack(">I", len(data)) + kind + data + crc

    head = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IEND", b"")


def _colour(data: bytes) -> object:
    return image_texture_from_bytes(
        data, source="t.png", srgb=True, wrap="repeat", filter="bilinear"
    )


def _alpha(data: bytes) -> object:
    return alpha_values(data, "t.png", luminance_without_alpha=True)  # decodes the pixels


@pytest.mark.parametrize("read", [_colour, _alpha])
@pytest.mark.parametrize(
    "data, needle",
    [
        (png_declaring(100_000, 100_000), f"expected at most {IMAGE_TEXELS_MAX:,} texels"),
        (png_declaring(2048, 2048), "image of 2048x2048 texels"),
        (b"hello, not a png", "not a format PIL knows"),
        (png_declaring(4, 4), "cannot read it as an image"),  # header only: no pixel data
    ],
    ids=["bomb", "too-large", "not-an-image", "no-pixels"],
)
def test_a_bomb_or_a_non_image_is_one_line(read, data, needle):
    with pytest.raises(SceneError, match="t.png") as info:
        read(data)
    message = str(info.value)
    assert needle in message and "\n" not in message and "BytesIO" not in message
