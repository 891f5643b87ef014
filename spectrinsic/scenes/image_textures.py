"""Image textures (RGB texels) as exact spectral textures: the decoded image record and the
corner weights that make every texel's spectrum linear in its linear RGB.

The upsampling is the one of ``rgb:R,G,B`` (:mod:`spectrinsic.spectra.user_spectra`): Mallett &
Yuksel's (2019) three non-negative sRGB basis spectra, ``ρ(λ) = R b_R(λ) + G b_G(λ) + B b_B(λ)``
(colour-science's ``MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019``; b_R + b_G + b_B = 1 within 1e-3 on
400-700 nm, every b in [0, 1]). On the 31 bands a texel's reflectance is therefore the fixed
31 × 3 matrix ``B`` times its linear RGB, and its reflectance layers follow in closed form.

The renderer's texture route (:mod:`spectrinsic.scenes.textures`) keeps each texel a *convex*
mix of basis materials, so the linear map is written over the 8 corners of the RGB cube
(:data:`CORNERS`, the spectra ``rgb:c_R,c_G,c_B`` with ``c ∈ {0, 1}³``): the trilinear weights
``w_c = Π_i (x_i if c_i else 1 − x_i)`` are non-negative, sum to 1 and satisfy
``Σ_c w_c c = x``, so ``Σ_c w_c ρ_c = R b_R + G b_G + B b_B`` exactly (:func:`corner_weights`).

Decoding (:func:`image_texture_from_file`): 8-bit images (PIL modes ``1 L LA P RGB RGBA``) are
read, sRGB-encoded ones decoded with the sRGB transfer function (colour-science), then multiplied
by the material's linear colour factor (glTF ``baseColorFactor``, MTL ``Kd``). Texels outside
[0, 1] (a factor above 1) are clipped to [0, 1] in linear RGB and the count is said in one line.
Texels are inside the sRGB gamut by construction (an 8-bit sRGB image cannot leave it). Alpha is
not read (surfaces are opaque; a texture with alpha below 1 says so in one line). Rows are
stored with row 0 at v = 0 (OpenGL / OBJ convention: the image's *bottom* row), the order
:func:`~spectrinsic.scenes.textures.texel_index` reads.

Untrusted input: an image of more than :data:`IMAGE_TEXELS_MAX` texels (after repetition for
``repeat`` wrapping) is refused from its header, before it is decoded.
"""

from __future__ import annotations

import base64
import contextlib
import hashlib
import io
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from ..errors import SceneError, SpectrinsicWarning
from ..spectra.colorimetry import decode_srgb

if TYPE_CHECKING:
    from PIL.Image import Image as PILImage

__all__ = [
    "CORNERS",
    "IMAGE_TEXELS_MAX",
    "WRAP_MODES",
    "FILTERS",
    "ImageTexture",
    "AssetColour",
    "corner_spectra",
    "corner_weights",
    "decode_texels",
    "image_texture_from_file",
    "opened_image",
    "image_texture_from_bytes",
    "image_from_record",
]

#: The RGB cube's corners, in the order of the corner weights (R varies fastest).
CORNERS: tuple[tuple[int, int, int], ...] = tuple(
    (r, g, b) for b in (0, 1) for g in (0, 1) for r in (0, 1)
)
#: Most texels of one image texture (after repetition): 1024 × 1024. The renderer holds
#: 8 corner weights and K band albedos per texel (about 200 MB at this size).
IMAGE_TEXELS_MAX = 1 << 20
#: Wrap modes of texture coordinates outside [0, 1] (glTF sampler / Mitsuba ``wrap_mode``).
WRAP_MODES = ("repeat", "clamp", "mirror")
#: Texture filters an asset may ask for; the renderer looks up the nearest texel.
FILTERS = ("nearest", "bilinear", "cubic")
_MODES = ("1", "L", "LA", "P", "RGB", "RGBA")

Wrap = Literal["repeat", "clamp", "mirror"]
Filter = Literal["nearest", "bilinear", "cubic"]


@dataclass(frozen=True, eq=False)
class ImageTexture:
    """A decoded image texture (module docstring).

    Attributes
    ----------
    source
        The image's path relative to the scene's folder (``"tex/checker.png"``), or ``""``
        for texels given in memory.
    sha256
        SHA-256 of the image file (hex), or ``""``.
    texels
        ``(h, w, 3)`` float64 linear sRGB in [0, 1], row 0 at v = 0 (the image's bottom row).
    wrap
        How coordinates outside [0, 1] are mapped (:data:`WRAP_MODES`).
    filter
        The filter the asset asks for (:data:`FILTERS`); the band path reads the nearest texel,
        so ``bilinear`` and ``cubic`` are rendered nearest (said once when the scene is read).
    tiles
        ``(rows, columns)`` copies of the image the renderer's texture holds, so that the
        asset's coordinates outside [0, 1] wrap exactly under ``repeat`` and ``mirror``
        (1, 1 otherwise); :func:`~spectrinsic.scenes.textures.image_weights`.
    first_tile
        ``(v, u)`` integer index of the first copy (copies with an odd index are flipped under
        ``mirror``).
    data, srgb, factor
        The image file's bytes (base64), its encoding and the factor the texels were decoded
        with (:func:`image_texture_from_bytes`), or ``""`` for texels given in memory. The
        scene record (``scene.json``) keeps these instead of the texels, which
        :func:`texture_from_record <spectrinsic.scenes.textures.texture_from_record>` decodes
        again: a 1024² image is its file's size there, not 67 MB of numbers.
    """

    source: str
    sha256: str
    # an image read from a file is recorded by its bytes (data), the texels derived from them
    texels: np.ndarray = field(metadata={"omit_when": lambda image: bool(image.data)})
    wrap: Wrap = "repeat"
    filter: Filter = "bilinear"
    tiles: tuple[int, int] = field(default=(1, 1))
    first_tile: tuple[int, int] = field(default=(0, 0))
    data: str = field(default="", metadata={"omit_default": True})
    srgb: bool = field(default=False, metadata={"omit_default": True})
    factor: tuple[float, float, float] = field(
        default=(1.0, 1.0, 1.0), metadata={"omit_default": True}
    )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ImageTexture):
            return NotImplemented

        def key(image: ImageTexture) -> tuple:
            return (
                image.source,
                image.sha256,
                image.wrap,
                image.filter,
                *image.tiles,
                *image.first_tile,
                image.data,
                image.srgb,
                *image.factor,
            )

        return key(self) == key(other) and np.array_equal(self.texels, other.texels)

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class AssetColour:
    """The colour an asset's material states: a constant reflectance (``spectrum``, a registry
    name such as ``rgb:0.8,0.2,0.1``) or an :class:`ImageTexture` (``image``), not both."""

    spectrum: str | None = None
    image: ImageTexture | None = None


def corner_spectra() -> tuple[str, ...]:
    """Registry names of the 8 corner reflectances, in :data:`CORNERS` order.

    >>> corner_spectra()[:2]
    ('rgb:0,0,0', 'rgb:1,0,0')
    """
    return tuple("rgb:" + ",".join(str(c) for c in corner) for corner in CORNERS)


def corner_weights(rgb: np.ndarray) -> np.ndarray:
    """``(..., 8)`` trilinear weights over :data:`CORNERS` of ``(..., 3)`` linear *rgb* in
    [0, 1]: non-negative, summing to 1, with ``weights @ CORNERS == rgb``.

    >>> w = corner_weights(np.array([0.25, 0.5, 1.0]))
    >>> bool(np.isclose(w.sum(), 1.0)), (w @ np.array(CORNERS)).tolist()
    (True, [0.25, 0.5, 1.0])
    """
    x = np.asarray(rgb, np.float64)
    corners = np.array(CORNERS, np.float64)
    return np.prod(np.where(corners == 1, x[..., None, :], 1.0 - x[..., None, :]), axis=-1)


def decode_texels(
    encoded: np.ndarray, *, srgb: bool, factor: tuple[float, float, float], what: str
) -> np.ndarray:
    """``(h, w, 3)`` linear texels in [0, 1] of ``(h, w, 3)`` *encoded* values in [0, 1]
    (sRGB-decoded if *srgb*), times the linear *factor*, clipped with one line naming *what*."""
    values = np.asarray(encoded, np.float64)
    if srgb:
        values = decode_srgb(values)  # the one sRGB decoding (colour-science's)
    values = values * np.asarray(factor, np.float64)
    outside = int(np.count_nonzero(np.any((values < 0) | (values > 1), axis=-1)))
    if outside:
        warnings.warn(
            f"{what}: {outside} texels outside [0, 1] in linear RGB clipped to [0, 1]",
            SpectrinsicWarning,
            stacklevel=2,
        )
    return np.clip(values, 0.0, 1.0)


@contextlib.contextmanager
def opened_image(data: bytes, what: str) -> Iterator[PILImage]:
    """The image file *data* opened by PIL, of at most :data:`IMAGE_TEXELS_MAX` texels; an
    unreadable file or a larger declared size (a decompression bomb: PIL's own limit raises
    ``DecompressionBombError`` before this check) is refused in one line naming *what*."""
    from PIL import Image

    try:
        with Image.open(io.BytesIO(data)) as img:
            w, h = img.size
            if w * h > IMAGE_TEXELS_MAX:
                raise SceneError(
                    f"{what}: image of {w}x{h} texels; expected at most "
                    f"{IMAGE_TEXELS_MAX:,} texels (downsize it)"
                )
            yield img
    except Image.DecompressionBombError:
        raise SceneError(
            f"{what}: image of more than {2 * (Image.MAX_IMAGE_PIXELS or 0):,} texels; expected "
            f"at most {IMAGE_TEXELS_MAX:,} texels (downsize it)"
        ) from None
    except Image.UnidentifiedImageError:  # its message holds the BytesIO's repr
        raise SceneError(
            f"{what}: cannot read it as an image (not a format PIL knows: PNG, JPEG, ...)"
        ) from None
    except OSError as exc:
        raise SceneError(f"{what}: cannot read it as an image ({exc})") from None


def _read_pixels(data: bytes, what: str) -> np.ndarray:
    """``(h, w, 3)`` values in [0, 1] of the 8-bit image file *data* (top row first)."""
    with opened_image(data, what) as img:
        if img.mode not in _MODES:
            raise SceneError(f"{what}: image mode {img.mode!r}; expected 8-bit {', '.join(_MODES)}")
        alpha = img.mode in ("LA", "RGBA") and np.asarray(img.getchannel("A")).min() < 255
        pixels = np.asarray(img.convert("RGB"), np.float64) / 255.0  # OSError: opened_image's
    if alpha:
        warnings.warn(
            f"{what}: alpha below 1 is not read (surfaces are opaque)",
            SpectrinsicWarning,
            stacklevel=3,
        )
    return pixels


def image_texture_from_file(
    path: str | Path,
    *,
    root: str | Path,
    srgb: bool,
    wrap: Wrap = "repeat",
    filter: Filter = "bilinear",  # noqa: A002 - the asset's own word (glTF, Mitsuba)
    factor: tuple[float, float, float] = (1.0, 1.0, 1.0),
) -> ImageTexture:
    """The :class:`ImageTexture` of the image at *path*, which must lie inside the scene's
    folder *root* (module docstring).

    Parameters
    ----------
    path
        The image, absolute or relative to *root*.
    srgb
        Whether the values are sRGB-encoded (glTF ``baseColorTexture``, MTL ``map_Kd``, a
        Mitsuba ``bitmap`` without ``raw``); ``False``: linear.
    wrap, filter
        The asset's wrap mode and filter (:data:`WRAP_MODES`, :data:`FILTERS`).
    factor
        Linear RGB multiplying every texel (glTF ``baseColorFactor``, MTL ``Kd``).

    Raises
    ------
    SceneError
        One line naming the file: outside *root*, missing, unreadable, too large, or an
        unknown wrap mode or filter.
    """
    base = Path(root).resolve()
    full = (base / path).resolve()
    what = f"texture {path}"
    if not full.is_relative_to(base):
        raise SceneError(f"{what}: lies outside the scene's folder {base}")
    if not full.is_file():
        raise SceneError(f"{what}: no such file in {base}")
    return image_texture_from_bytes(
        full.read_bytes(),
        source=full.relative_to(base).as_posix(),
        srgb=srgb,
        wrap=wrap,
        filter=filter,
        factor=factor,
    )


def image_texture_from_bytes(
    data: bytes,
    *,
    source: str,
    srgb: bool,
    wrap: Wrap = "repeat",
    filter: Filter = "bilinear",  # noqa: A002 - the asset's own word (glTF, Mitsuba)
    factor: tuple[float, float, float] = (1.0, 1.0, 1.0),
) -> ImageTexture:
    """The :class:`ImageTexture` of the image file's bytes *data* (PNG, JPEG...), named
    *source* (a path relative to the scene, or ``"scene.glb#images/0"`` for an embedded one);
    the other parameters as :func:`image_texture_from_file`."""
    what = f"texture {source}"
    if wrap not in WRAP_MODES or filter not in FILTERS:
        raise SceneError(
            f"{what}: wrap {wrap!r} and filter {filter!r}; expected one of "
            f"{', '.join(WRAP_MODES)} and one of {', '.join(FILTERS)}"
        )
    texels = decode_texels(_read_pixels(data, what), srgb=srgb, factor=factor, what=what)
    return ImageTexture(
        source=source,
        sha256=hashlib.sha256(data).hexdigest(),
        texels=np.ascontiguousarray(texels[::-1]),  # row 0 at v = 0: the bottom row
        wrap=wrap,
        filter=filter,
        data=base64.b64encode(data).decode("ascii"),
        srgb=bool(srgb),
        factor=(float(factor[0]), float(factor[1]), float(factor[2])),
    )


def _pair(values: Any) -> tuple[int, int]:
    return int(values[0]), int(values[1])


def image_from_record(record: Mapping[str, Any]) -> ImageTexture:
    """The :class:`ImageTexture` of its ``scene_to_dict`` record: decoded again from its file's
    bytes (checked against its SHA-256), or its texels as written."""
    source, sha = str(record["source"]), str(record["sha256"])
    wrap, filt = record.get("wrap", "repeat"), record.get("filter", "bilinear")
    tiles, first = _pair(record.get("tiles", (1, 1))), _pair(record.get("first_tile", (0, 0)))
    if not record.get("data"):
        texels = np.asarray(record["texels"], np.float64)
        return ImageTexture(source, sha, texels, wrap, filt, tiles, first)
    data = base64.b64decode(str(record["data"]))
    if hashlib.sha256(data).hexdigest() != sha:
        raise SceneError(f"texture {source}: its bytes do not match its SHA-256")
    r, g, b = (float(c) for c in record.get("factor", (1.0, 1.0, 1.0)))
    with warnings.catch_warnings():  # said when the asset was read
        warnings.simplefilter("ignore", SpectrinsicWarning)
        image = image_texture_from_bytes(
            data,
            source=source,
            srgb=bool(record.get("srgb", False)),
            wrap=wrap,
            filter=filt,
            factor=(r, g, b),
        )
    return replace(image, tiles=tiles, first_tile=first)
