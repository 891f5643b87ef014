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

Patterns (:data:`PATTERNS`) are generated here (licence: spectrinsic's own): ``rings`` (wood
grain: rings around a centre, perturbed by value noise), ``weave`` (fabric: two crossing sets of
threads) and ``noise`` (fractal value noise, stone). Each gives a field ``t`` in [0, 1], quantised
to steps of 1/255, mapped onto the basis by piecewise-linear interpolation along the basis order.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import did_you_mean

__all__ = [
    "PATTERNS",
    "TEXTURE_MAX",
    "BASIS_MAX",
    "CONVEX_TOLERANCE",
    "Texture",
    "basis_name",
    "make_texture",
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
    """

    name: str
    basis: tuple[int, ...]
    # a procedural texture's record (scene_to_dict, the scene hash) is its recipe alone
    weights: np.ndarray = field(metadata={"omit_when": lambda texture: bool(texture.pattern)})
    pattern: str = field(default="", metadata={"omit_default": True})
    size: int = field(default=0, metadata={"omit_default": True})
    seed: int = field(default=0, metadata={"omit_default": True})

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Texture):
            return NotImplemented
        return (
            (self.name, self.basis, self.pattern, self.size, self.seed)
            == (other.name, other.basis, other.pattern, other.size, other.seed)
            and self.weights.shape == other.weights.shape
            and np.array_equal(self.weights, other.weights)
        )

    __hash__ = None  # type: ignore[assignment]


def basis_name(texture: str, b: int) -> str:
    """Name of basis material *b* of textured material *texture* in a scene (``"table[0]"``).

    >>> basis_name("table", 0)
    'table[0]'
    """
    return f"{texture}[{b}]"


def weights_problem(weights: np.ndarray) -> str | None:
    """What is wrong with ``(h, w, B)`` texel *weights* (one phrase), or ``None``."""
    w = np.asarray(weights)
    if w.ndim != 3 or not 2 <= w.shape[2] <= BASIS_MAX:
        return f"texture weights of shape {w.shape}: expected (h, w, B) with 2 <= B <= {BASIS_MAX}"
    if not (1 <= w.shape[0] <= TEXTURE_MAX and 1 <= w.shape[1] <= TEXTURE_MAX):
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
    if not 2 <= len(basis) <= BASIS_MAX or len(set(basis)) != len(basis):
        return f"texture basis {basis}: expected 2 to {BASIS_MAX} distinct materials"
    if any(not 0 <= b < len(kinds) for b in basis):
        return f"texture basis {basis}: material index out of range 0..{len(kinds) - 1}"
    glossy = [b for b in basis if kinds[b] != "diffuse"]
    if glossy:
        return f"texture basis material {glossy[0]} is {kinds[glossy[0]]}; expected diffuse"
    problem = weights_problem(texture.weights)
    if problem is None and texture.weights.shape[2] != len(basis):
        problem = f"texture weights have {texture.weights.shape[2]} channels for {len(basis)} basis spectra"
    if problem is None and np.any(np.asarray(face_materials) != basis[0]):
        problem = f"a textured mesh's faces all take material basis[0] = {basis[0]}"
    return problem


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


def texture_from_record(record: Mapping[str, Any]) -> Texture:
    """The :class:`Texture` of its ``scene_to_dict`` record (a recipe, or explicit weights)."""
    basis = tuple(int(b) for b in record["basis"])
    if record.get("pattern"):
        return make_texture(
            str(record["name"]),
            basis,
            str(record["pattern"]),
            int(record.get("size", 0)),
            int(record.get("seed", 0)),  # left out of the record at its default, 0
        )
    return Texture(str(record["name"]), basis, np.asarray(record["weights"], np.float64))


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
