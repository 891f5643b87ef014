"""Spectral textures: per-texel convex mixes of a few basis reflectances, on a mesh.

A :class:`Texture` holds ``weights`` ``(h, w, B)``: at texel ``(i, j)`` the reflectance is

    ρ_ij(λ) = Σ_b weights[i, j, b] · ρ_b(λ),   weights ≥ 0,  Σ_b weights[i, j, b] = 1,

a convex mix of the ``B`` basis spectra ρ_b (each in [0, 1]), so every texel is a physically
valid reflectance in [0, 1] with no clipping. The basis spectra are ordinary diffuse entries of
``Scene.materials`` (``Texture.basis`` holds their indices); everything linear in the material
(band albedo, reflectance under D65, camera responses) is then the same mix of the basis values.

Texture coordinates come from one rule, :func:`box_uv`: each face is projected along the axis its
normal is closest to, onto the other two axes, normalised by the mesh's bounding box, so
``(u, v)`` lies in [0, 1]. Lookup is nearest-texel (:func:`texel_index`): texel ``(i, j)``
covers ``u ∈ [j/w, (j+1)/w)``, ``v ∈ [i/h, (i+1)/h)`` (row 0 at v = 0), clamped at the edges.

Image textures (:mod:`spectrinsic.scenes.image_textures`, issue 41) are the same record with
the 8 RGB-cube corner spectra as basis, the image's trilinear corner weights as ``weights``
(:func:`make_image_texture`) and the asset's own coordinates in ``uv`` instead of the box
projection; ``repeat`` and ``mirror`` wrapping outside [0, 1] are made exact by copying the
image (flipped for ``mirror``) in the texel table and rescaling ``uv`` into [0, 1].

Patterns (:data:`PATTERNS`) are generated here (licence: spectrinsic's own): ``rings`` (wood
grain: rings around a centre, perturbed by value noise), ``weave`` (fabric: two crossing sets of
threads) and ``noise`` (fractal value noise, stone). Each gives a field ``t`` in [0, 1], quantised
to steps of 1/255, mapped onto the basis by piecewise-linear interpolation along the basis order.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import SceneError, SpectrinsicWarning, did_you_mean
from .image_textures import (
    CORNERS,
    IMAGE_TEXELS_MAX,
    ImageTexture,
    corner_weights,
    image_from_record,
)

__all__ = [
    "PATTERNS",
    "TEXTURE_MAX",
    "BASIS_MAX",
    "CONVEX_TOLERANCE",
    "Texture",
    "basis_name",
    "make_texture",
    "make_image_texture",
    "image_weights",
    "texture_from_record",
    "pattern_weights",
    "weights_problem",
    "texture_problem",
    "box_uv",
    "texel_index",
]

#: Procedural patterns :func:`pattern_weights` knows.
PATTERNS = ("rings", "weave", "noise")
#: Largest texture side in texels (bounds memory and scene files).
TEXTURE_MAX = 256
#: Most basis spectra in one texture.
BASIS_MAX = 4
#: How far a texel's weights may sum from 1 (they are renormalised within it).
CONVEX_TOLERANCE = 1e-6
_LEVELS = 255


@dataclass(frozen=True, eq=False)
class Texture:
    """A spectral texture on one mesh (module docstring).

    Attributes
    ----------
    name
        Name of the textured material in scene files (``"wood"``).
    basis
        Indices into ``Scene.materials`` of the basis reflectances (diffuse materials).
    weights
        ``(h, w, B)`` float64 convex weights per texel (row 0 at v = 0).
    pattern, size, seed
        The procedural recipe the weights came from (:func:`make_texture`), or ``""`` (and 0)
        for weights given explicitly.
    uv
        ``(F, 3, 2)`` texture coordinates in [0, 1] of each face corner of the mesh (an image
        texture's, from the asset), or ``None``: :func:`box_uv`.
    image
        The decoded image the weights came from (:func:`make_image_texture`), or ``None``.
    """

    name: str
    basis: tuple[int, ...]
    # a procedural texture's record (scene_to_dict, the scene hash) is its recipe alone
    weights: np.ndarray = field(
        metadata={"omit_when": lambda texture: bool(texture.pattern) or texture.image is not None}
    )
    pattern: str = field(default="", metadata={"omit_default": True})
    size: int = field(default=0, metadata={"omit_default": True})
    seed: int = field(default=0, metadata={"omit_default": True})
    uv: np.ndarray | None = field(
        default=None, metadata={"omit_when": lambda texture: texture.uv is None}
    )
    image: ImageTexture | None = field(
        default=None, metadata={"omit_when": lambda texture: texture.image is None}
    )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Texture):
            return NotImplemented
        return (
            (self.name, self.basis, self.pattern, self.size, self.seed)
            == (other.name, other.basis, other.pattern, other.size, other.seed)
            and self.weights.shape == other.weights.shape
            and np.array_equal(self.weights, other.weights)
            and _same_uv(self.uv, other.uv)
            and self.image == other.image
        )

    __hash__ = None  # type: ignore[assignment]


def _same_uv(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    return a is None and b is None or (a is not None and b is not None and np.array_equal(a, b))


def basis_name(texture: str, b: int) -> str:
    """Name of basis material *b* of textured material *texture* in a scene (``"table[0]"``).

    >>> basis_name("table", 0)
    'table[0]'
    """
    return f"{texture}[{b}]"


def weights_problem(weights: np.ndarray, *, image: bool = False) -> str | None:
    """What is wrong with ``(h, w, B)`` texel *weights* (one phrase), or ``None``; an *image*
    texture's have the 8 corner weights and at most ``IMAGE_TEXELS_MAX`` texels."""
    w = np.asarray(weights)
    most = len(CORNERS) if image else BASIS_MAX
    if w.ndim != 3 or not 2 <= w.shape[2] <= most:
        return f"texture weights of shape {w.shape}: expected (h, w, B) with 2 <= B <= {most}"
    if image and not (1 <= w.shape[0] * w.shape[1] <= IMAGE_TEXELS_MAX):
        return f"texture of {w.shape[0]}x{w.shape[1]} texels: expected at most {IMAGE_TEXELS_MAX:,}"
    if not image and not (1 <= w.shape[0] <= TEXTURE_MAX and 1 <= w.shape[1] <= TEXTURE_MAX):
        return (
            f"texture of {w.shape[0]}x{w.shape[1]} texels: expected at most {TEXTURE_MAX} per side"
        )
    if not np.issubdtype(w.dtype, np.number) or not np.all(np.isfinite(w)):
        return "texture weights: expected finite numbers"
    if np.any(w < 0):
        return "texture weights are not convex: a weight is negative"
    worst = float(np.max(np.abs(w.sum(axis=2) - 1.0)))
    if worst > CONVEX_TOLERANCE:
        return f"texture weights are not convex: a texel's weights sum {worst:.3g} away from 1"
    return None


def texture_problem(
    texture: Texture, face_materials: np.ndarray, kinds: Sequence[str]
) -> str | None:
    """What is wrong with *texture* on a mesh with *face_materials*, in a scene whose materials
    have *kinds* (one phrase), or ``None``."""
    basis = texture.basis
    most = BASIS_MAX if texture.image is None else len(CORNERS)
    if not 2 <= len(basis) <= most or len(set(basis)) != len(basis):
        return f"texture basis {basis}: expected 2 to {most} distinct materials"
    if any(not 0 <= b < len(kinds) for b in basis):
        return f"texture basis {basis}: material index out of range 0..{len(kinds) - 1}"
    glossy = [b for b in basis if kinds[b] != "diffuse"]
    if glossy:
        return f"texture basis material {glossy[0]} is {kinds[glossy[0]]}; expected diffuse"
    problem = weights_problem(texture.weights, image=texture.image is not None)
    if problem is None and texture.weights.shape[2] != len(basis):
        problem = f"texture weights have {texture.weights.shape[2]} channels for {len(basis)} basis spectra"
    if problem is None and np.any(np.asarray(face_materials) != basis[0]):
        problem = f"a textured mesh's faces all take material basis[0] = {basis[0]}"
    if problem is None and texture.uv is not None:
        problem = _uv_problem(texture.uv, len(np.asarray(face_materials)))
    return problem


def _uv_problem(uv: np.ndarray, n_faces: int) -> str | None:
    """What is wrong with a texture's corner *uv* on a mesh of *n_faces* faces, or ``None``."""
    a = np.asarray(uv)
    if a.shape != (n_faces, 3, 2):
        return f"texture uv of shape {a.shape}: expected ({n_faces}, 3, 2), one per face corner"
    if not np.issubdtype(a.dtype, np.number) or not np.all(np.isfinite(a)):
        return "texture uv: expected finite numbers"
    return None


def _value_noise(rng: np.random.Generator, size: int, cells: int) -> np.ndarray:
    """``(size, size)`` smooth value noise in [0, 1]: random lattice values, smoothstep-blended."""
    lattice = rng.random((cells + 1, cells + 1))
    x = (np.arange(size) + 0.5) / size * cells
    i = np.minimum(x.astype(np.int64), cells - 1)
    f = x - i
    s = f * f * (3.0 - 2.0 * f)
    rows = lattice[i] * (1 - s)[:, None] + lattice[i + 1] * s[:, None]
    return rows[:, i] * (1 - s)[None, :] + rows[:, i + 1] * s[None, :]


def _field(pattern: str, size: int, rng: np.random.Generator) -> np.ndarray:
    """The pattern's ``(size, size)`` field in [0, 1]."""
    y, x = np.mgrid[0:size, 0:size] / size + 0.5 / size
    if pattern == "rings":
        cx, cy, freq = rng.uniform(-0.6, -0.2), rng.uniform(0.2, 0.8), rng.uniform(6.0, 10.0)
        r = np.hypot(x - cx, (y - cy) * 0.35) + 0.08 * _value_noise(rng, size, 4)
        phase = (r * freq) % 1.0
        return phase**2  # slow early wood, sharp late-wood edge
    if pattern == "weave":
        threads = int(rng.integers(6, 13))
        wx, wy = np.sin(np.pi * x * threads) ** 2, np.sin(np.pi * y * threads) ** 2
        over = (np.floor(x * threads) + np.floor(y * threads)) % 2 == 0
        return np.where(over, 0.15 + 0.7 * wx, 0.85 - 0.7 * wy) * (
            0.9 + 0.1 * _value_noise(rng, size, 8)
        )
    octaves = [_value_noise(rng, size, c) * a for c, a in ((3, 0.5), (6, 0.3), (12, 0.2))]
    return np.clip(sum(octaves, np.zeros((size, size))), 0.0, 1.0)


def pattern_weights(pattern: str, size: int, n_basis: int, seed: int) -> np.ndarray:
    """``(size, size, n_basis)`` convex weights of a procedural *pattern* (module docstring).

    The field ``t`` is quantised to multiples of 1/255 and placed at ``p = t (B - 1)`` along the
    basis: weight ``1 - (p - ⌊p⌋)`` on basis ``⌊p⌋`` and ``p - ⌊p⌋`` on the next, so each texel
    mixes at most two neighbouring basis spectra and its weights sum to 1 exactly.

    >>> w = pattern_weights("noise", 8, 3, seed=1)
    >>> w.shape, bool(np.all(w >= 0)), bool(np.allclose(w.sum(axis=2), 1.0))
    ((8, 8, 3), True, True)
    """
    if pattern not in PATTERNS:
        raise ValueError(
            f"texture pattern {pattern!r}: expected one of {', '.join(PATTERNS)}"
            + did_you_mean(pattern, PATTERNS)
        )
    t = np.round(_field(pattern, size, np.random.default_rng(seed)) * _LEVELS) / _LEVELS
    p = t * (n_basis - 1)
    lo = np.minimum(np.floor(p).astype(np.int64), n_basis - 2)
    frac = p - lo
    out = np.zeros((size, size, n_basis))
    np.put_along_axis(out, lo[..., None], (1.0 - frac)[..., None], axis=2)
    np.put_along_axis(out, lo[..., None] + 1, frac[..., None], axis=2)
    return out


def make_texture(name: str, basis: tuple[int, ...], pattern: str, size: int, seed: int) -> Texture:
    """The :class:`Texture` of a procedural *pattern* of ``size × size`` texels over *basis*."""
    if not 1 <= size <= TEXTURE_MAX:
        raise ValueError(f"texture size {size}: expected 1..{TEXTURE_MAX} texels per side")
    weights = pattern_weights(pattern, size, len(basis), seed)
    return Texture(name, tuple(basis), weights, pattern, int(size), int(seed))


def image_weights(image: ImageTexture) -> np.ndarray:
    """``(h·rows, w·columns, 8)`` corner weights of *image*'s texels
    (:func:`~spectrinsic.scenes.image_textures.corner_weights`) in ``image.tiles`` copies,
    from copy ``image.first_tile`` on; under ``mirror`` a copy with an odd index is flipped."""
    weights = corner_weights(image.texels)
    rows, cols = (int(t) for t in image.tiles)
    row0, col0 = (int(t) for t in image.first_tile)
    mirror = image.wrap == "mirror"
    line = [weights[:, ::-1] if mirror and (col0 + c) % 2 else weights for c in range(cols)]
    strip = np.concatenate(line, axis=1)
    return np.concatenate(
        [strip[::-1] if mirror and (row0 + r) % 2 else strip for r in range(rows)], axis=0
    )


def _wrapped(uv: np.ndarray, image: ImageTexture, what: str) -> tuple[np.ndarray, ImageTexture]:
    """*uv* rescaled into [0, 1] and *image* with the copies that make its wrap mode exact
    under the renderer's clamped nearest lookup (:attr:`ImageTexture.tiles`)."""
    inside = bool(np.all(uv >= 0.0) and np.all(uv <= 1.0))
    if inside or image.wrap == "clamp":
        return uv, replace(image, tiles=(1, 1), first_tile=(0, 0))
    lo, hi = np.floor(uv.min(axis=(0, 1))), np.ceil(uv.max(axis=(0, 1)))
    span = np.maximum(hi - lo, 1.0)
    cols, rows = int(span[0]), int(span[1])
    h, w = image.texels.shape[:2]
    if h * w * rows * cols > IMAGE_TEXELS_MAX:
        raise SceneError(
            f"{what}: coordinates span {cols}x{rows} copies of a {w}x{h} image, more than "
            f"{IMAGE_TEXELS_MAX:,} texels"
        )
    tiled = replace(image, tiles=(rows, cols), first_tile=(int(lo[1]), int(lo[0])))
    return (uv - lo) / span, tiled


def make_image_texture(
    name: str, basis: tuple[int, ...], image: ImageTexture, uv: np.ndarray
) -> Texture:
    """The :class:`Texture` of *image* on a mesh whose face corners have texture coordinates
    *uv* ``(F, 3, 2)`` (the asset's; v up, OpenGL convention), over *basis*: the indices of the
    8 corner materials (:data:`~spectrinsic.scenes.image_textures.CORNERS` order)."""
    if len(basis) != len(CORNERS):
        raise ValueError(f"image texture basis {basis}: expected the {len(CORNERS)} corners")
    uv = np.asarray(uv, np.float64)
    if uv.ndim != 3 or uv.shape[1:] != (3, 2) or not np.all(np.isfinite(uv)):
        raise SceneError(f"texture {image.source or name}: expected finite (F, 3, 2) uv")
    what = f"texture {image.source or name}"
    scaled, tiled = _wrapped(uv, image, what)
    if image.filter != "nearest":
        warnings.warn(
            f"{what}: {image.filter} filtering approximated by the nearest texel "
            "(the band path's lookup; the ground truth is exact for what is rendered)",
            SpectrinsicWarning,
            stacklevel=2,
        )
    return Texture(name, tuple(basis), image_weights(tiled), uv=scaled, image=tiled)


def texture_from_record(record: Mapping[str, Any]) -> Texture:
    """The :class:`Texture` of its ``scene_to_dict`` record (a recipe, an image, or explicit
    weights)."""
    basis = tuple(int(b) for b in record["basis"])
    uv = None if record.get("uv") is None else np.asarray(record["uv"], np.float64)
    if record.get("image"):
        image = image_from_record(record["image"])
        return Texture(str(record["name"]), basis, image_weights(image), uv=uv, image=image)
    if record.get("pattern"):
        return make_texture(
            str(record["name"]),
            basis,
            str(record["pattern"]),
            int(record.get("size", 0)),
            int(record.get("seed", 0)),  # left out of the record at its default, 0
        )
    return Texture(str(record["name"]), basis, np.asarray(record["weights"], np.float64), uv=uv)


def box_uv(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """``(F, 3, 2)`` texture coordinates of each face corner in [0, 1] (module docstring).

    >>> v = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0.0]])
    >>> box_uv(v, np.array([[0, 1, 2]])).tolist()
    [[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]]
    """
    v = np.asarray(vertices, float)
    tri = v[np.asarray(faces, np.int64)]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    axis = np.argmax(np.abs(normal), axis=1)
    lo, extent = v.min(axis=0), np.ptp(v, axis=0)
    scaled = np.divide(tri - lo, extent, out=np.zeros_like(tri), where=extent > 0)
    # the two axes other than the face's normal axis, in cyclic order after x: (y, z), (x, z), (x, y)
    u_axis = np.where(axis == 0, 1, 0)
    v_axis = np.where(axis == 2, 1, 2)
    pick = [
        np.take_along_axis(scaled, np.repeat(a[:, None, None], 3, 1), 2) for a in (u_axis, v_axis)
    ]
    return np.concatenate(pick, axis=-1)


def texel_index(uv: np.ndarray, shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Row and column of the nearest texel of ``(..., 2)`` *uv* in a texture of *shape*
    ``(h, w)``, clamped at the edges (the lookup the renderer does).

    >>> texel_index(np.array([[0.0, 0.0], [0.99, 0.5], [1.0, 1.0]]), (4, 2))
    (array([0, 2, 3]), array([0, 1, 1]))
    """
    uv = np.asarray(uv, float)
    h, w = shape
    col = np.clip(np.floor(uv[..., 0] * w), 0, w - 1).astype(np.int64)
    row = np.clip(np.floor(uv[..., 1] * h), 0, h - 1).astype(np.int64)
    return row, col
