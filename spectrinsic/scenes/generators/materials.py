"""Reflectances and spatially varying paint for generated scenes.

Materials are drawn from the 1269 matte Munsell chips (and the SFU reflectances when a data
directory is configured), with a controllable distribution of Munsell value and chroma
(:class:`MaterialDistribution`). Patterns (:data:`PATTERNS`: stripes, checkers, patches,
printed labels, noise partitions, spectral textures) repaint faces by their centroids, so every
region is still one exact spectrum (no texture filtering); a spectral texture varies smoothly
from face to face as convex mixes of three reflectances (``mix:`` spectra). With
``texture_fraction`` an object instead takes a per-pixel spectral texture
(:data:`PIXEL_TEXTURE`, :mod:`spectrinsic.scenes.textures`).
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ...errors import SceneError
from ...spectra import list_spectra
from ..painting import patches, printed, stripes
from ..parts import Part
from ..textures import PATTERNS as TEXTURE_PATTERNS

__all__ = [
    "MaterialDistribution",
    "PATTERNS",
    "munsell_chips",
    "check_ranges",
    "within",
    "pixel_texture",
    "obeys",
    "repaint_outside",
    "draw_reflectance",
    "draw_palette",
    "paint",
    "PIXEL_TEXTURE",
]

_NOTATION = re.compile(r"^\S+ (\d+(?:\.\d+)?)/(\d+(?:\.\d+)?)$")


@dataclass(frozen=True)
class MaterialDistribution:
    """Which reflectances a generator draws.

    Attributes
    ----------
    value_range
        Munsell value (lightness, 0-10) interval of the chips drawn.
    chroma_range
        Munsell chroma interval of the chips drawn (0: grey; the matte set reaches 16).
    sfu_fraction
        Probability of drawing an SFU reflectance instead of a Munsell chip (only when the
        caller passes SFU names).
    pattern_probability
        Probability that an object is painted with a pattern of several spectra.
    texture_fraction
        Probability that an object instead takes a per-pixel spectral texture
        (:data:`PIXEL_TEXTURE`); 0 draws nothing, so scenes stay those of before.
    """

    value_range: tuple[float, float] = (2.0, 9.0)
    chroma_range: tuple[float, float] = (0.0, 16.0)
    sfu_fraction: float = 0.0
    pattern_probability: float = 0.5
    texture_fraction: float = 0.0

    def __post_init__(self) -> None:
        for name in ("value_range", "chroma_range"):
            lo, hi = getattr(self, name)
            if not lo <= hi:
                raise SceneError(f"material distribution {name}={(lo, hi)}; expected low <= high")
        for name in ("sfu_fraction", "pattern_probability", "texture_fraction"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise SceneError(
                    f"material distribution {name}={getattr(self, name)}; expected 0..1"
                )


@functools.lru_cache(maxsize=1)
def munsell_chips() -> tuple[tuple[str, float, float], ...]:
    """Every matte Munsell chip as ``(name, value, chroma)``, e.g. ``("munsell:5R 4/14", 4, 14)``."""
    out = []
    for name in list_spectra("munsell"):
        m = _NOTATION.match(name.split(":", 1)[1])
        if m:
            out.append((name, float(m.group(1)), float(m.group(2))))
    return tuple(out)


def _pool(value_range: tuple[float, float], chroma_range: tuple[float, float]) -> list[str]:
    (v0, v1), (c0, c1) = value_range, chroma_range
    return [n for n, v, c in munsell_chips() if v0 <= v <= v1 and c0 <= c <= c1]


def check_ranges(value_range: tuple[float, float], chroma_range: tuple[float, float]) -> None:
    """Refuse Munsell ranges that hold no matte chip (raises :class:`SceneError`, one line)."""
    if not value_range[0] <= value_range[1] or not chroma_range[0] <= chroma_range[1]:
        raise SceneError(
            f"value range {value_range} / chroma range {chroma_range}; expected LO <= HI"
        )
    if not _pool(value_range, chroma_range):
        raise SceneError(
            f"no Munsell chip has value in {value_range[0]:g}-{value_range[1]:g} and chroma in "
            f"{chroma_range[0]:g}-{chroma_range[1]:g}; the matte chips span value 2.5-9 and "
            "chroma 1-14"
        )


def within(preferred: MaterialDistribution, user: MaterialDistribution) -> MaterialDistribution:
    """*preferred* (a generator's own taste, e.g. light walls) narrowed to the *user*'s ranges;
    the user's ranges alone where the two share no chip. Either way every chip drawn obeys the
    user's ``--value-range`` / ``--chroma-range``."""
    v = (
        max(preferred.value_range[0], user.value_range[0]),
        min(preferred.value_range[1], user.value_range[1]),
    )
    c = (
        max(preferred.chroma_range[0], user.chroma_range[0]),
        min(preferred.chroma_range[1], user.chroma_range[1]),
    )
    if v[0] <= v[1] and c[0] <= c[1] and _pool(v, c):
        return MaterialDistribution(v, c, preferred.sfu_fraction, preferred.pattern_probability)
    return MaterialDistribution(
        user.value_range, user.chroma_range, preferred.sfu_fraction, preferred.pattern_probability
    )


def obeys(name: str, dist: MaterialDistribution) -> bool:
    """Whether *name* is a Munsell chip inside *dist*'s value and chroma ranges."""
    return name in _pool_set(dist.value_range, dist.chroma_range)


@functools.lru_cache(maxsize=32)
def _pool_set(
    value_range: tuple[float, float], chroma_range: tuple[float, float]
) -> frozenset[str]:
    return frozenset(_pool(value_range, chroma_range))


def repaint_outside(part: Part, rng: np.random.Generator, dist: MaterialDistribution) -> Part:
    """*part* with every palette entry outside *dist* (not a chip in its ranges) replaced by a
    chip drawn from *dist*; the regions keep their shapes (library objects keep their look
    where the ranges allow it)."""
    palette = tuple(n if obeys(n, dist) else draw_reflectance(rng, dist) for n in part.palette)
    return Part(part.vertices, part.faces, part.labels, palette)


def draw_reflectance(
    rng: np.random.Generator, dist: MaterialDistribution, sfu: Sequence[str] = ()
) -> str:
    """One reflectance name drawn from *dist* (Munsell, or SFU with ``dist.sfu_fraction``)."""
    if sfu and rng.random() < dist.sfu_fraction:
        return sfu[int(rng.integers(len(sfu)))]
    pool = _pool(dist.value_range, dist.chroma_range)
    if not pool:
        raise SceneError(
            f"no Munsell chip has value in {dist.value_range} and chroma in "
            f"{dist.chroma_range}; widen the ranges"
        )
    return pool[int(rng.integers(len(pool)))]


def draw_palette(
    rng: np.random.Generator, dist: MaterialDistribution, n: int, sfu: Sequence[str] = ()
) -> list[str]:
    """*n* distinct reflectance names (fewer only if the distribution has fewer)."""
    names: list[str] = []
    for _ in range(8 * n):
        name = draw_reflectance(rng, dist, sfu)
        if name not in names:
            names.append(name)
        if len(names) == n:
            break
    return names


def _labelled(part: Part, palette: Sequence[str], index: np.ndarray) -> Part:
    """*part* repainted: face f takes ``palette[index[f] % len(palette)]``."""
    names = tuple(dict.fromkeys(palette))
    lookup = np.array([names.index(p) for p in palette], dtype=np.int64)
    labels = lookup[np.asarray(index, dtype=np.int64) % len(palette)]
    used, labels = np.unique(labels, return_inverse=True)
    return Part(part.vertices, part.faces, labels.astype(np.int64), tuple(names[i] for i in used))


def _extent(part: Part) -> np.ndarray:
    return np.maximum(np.ptp(part.vertices, axis=0), 1e-6)


def _stripes(part: Part, rng: np.random.Generator, palette: Sequence[str]) -> Part:
    axis = int(rng.integers(3))
    width = float(_extent(part)[axis]) / rng.uniform(2, 8)
    return stripes(part, list(palette), axis=axis, width=width, offset=float(rng.uniform(0, width)))


def _checkers(part: Part, rng: np.random.Generator, palette: Sequence[str]) -> Part:
    cell = float(_extent(part).max()) / rng.uniform(2, 6)
    k = np.floor((part.centroids - part.vertices.min(axis=0)) / cell).astype(np.int64)
    return _labelled(part, palette, k.sum(axis=1))


def _patches(part: Part, rng: np.random.Generator, palette: Sequence[str]) -> Part:
    out = _labelled(part, palette[:1], np.zeros(len(part.faces)))
    centres = part.centroids[rng.integers(len(part.faces), size=int(rng.integers(1, 5)))]
    radius = float(_extent(part).max()) * rng.uniform(0.1, 0.3)
    for i, c in enumerate(centres):
        out = patches(out, palette[1 + i % max(1, len(palette) - 1)], [c], radius)
    return out


def _noise(part: Part, rng: np.random.Generator, palette: Sequence[str]) -> Part:
    """A Voronoi partition of the surface around random seed points (a noise-like partition)."""
    lo, hi = part.vertices.min(axis=0), part.vertices.max(axis=0)
    seeds = rng.uniform(lo, hi, size=(int(rng.integers(3, 12)), 3))
    cell = np.linalg.norm(part.centroids[:, None] - seeds[None], axis=-1).argmin(axis=1)
    return _labelled(part, palette, cell)


def _label(part: Part, rng: np.random.Generator, palette: Sequence[str]) -> Part:
    """A printed-paper-like label on the side facing -y: random ink rows on the base colour."""
    lo, hi = part.vertices.min(axis=0), part.vertices.max(axis=0)
    cols, nrows = int(rng.integers(4, 10)), int(rng.integers(3, 8))
    cell = float(min(hi[0] - lo[0], hi[2] - lo[2])) / max(cols, nrows)
    legend = {chr(65 + i): p for i, p in enumerate(palette[1:])} or {"A": palette[0]}
    keys = [*legend, ".", "."]
    rows = ["".join(keys[int(k)] for k in rng.integers(len(keys), size=cols)) for _ in range(nrows)]
    base = _labelled(part, palette[:1], np.zeros(len(part.faces)))
    return printed(
        base,
        rows,
        legend,
        origin=(float(lo[0]), float(lo[2])),
        cell=cell,
        axes=(0, 2),
        facing=(0, -1, 0),
    )


#: Steps of a spectral texture's mixing weights (1/8: at most 45 mixes of three reflectances).
TEXTURE_STEPS = 8


def _quantised(weights: np.ndarray, steps: int) -> np.ndarray:
    """Rows of *weights* (summing to 1) as whole multiples of 1/steps still summing to 1
    (largest remainders get the spare steps)."""
    scaled = weights * steps
    out = np.floor(scaled).astype(np.int64)
    spare = steps - out.sum(axis=1)
    order = np.argsort(-(scaled - out), axis=1)
    for j in range(weights.shape[1]):
        out[np.arange(len(out)), order[:, j]] += (spare > j).astype(np.int64)
    return out


def _texture(part: Part, rng: np.random.Generator, palette: Sequence[str]) -> Part:
    """A spectral texture: every face (texel) is a convex mix ``mix:w1*A+w2*B+w3*C`` of up to
    three palette reflectances, so it is a valid reflectance in [0, 1]; the weights vary
    smoothly over the surface (softmax of random low-frequency sinusoids of the position),
    quantised to 1/TEXTURE_STEPS. Each texel stays one exact spectrum."""
    bases = list(dict.fromkeys(palette))[:3]
    p = (part.centroids - part.vertices.min(axis=0)) / float(_extent(part).max())
    fields = [
        np.sin(2 * np.pi * p @ rng.uniform(0.3, 1.5, 3) + rng.uniform(0, 2 * np.pi)) for _ in bases
    ]
    raw = np.exp(2.0 * np.stack(fields, axis=1))
    steps = _quantised(raw / raw.sum(axis=1, keepdims=True), TEXTURE_STEPS)
    rows, index = np.unique(steps, axis=0, return_inverse=True)
    names = []
    for row in rows:
        terms = [(int(k), b) for k, b in zip(row, bases, strict=True) if k > 0]
        names.append(
            terms[0][1]
            if len(terms) == 1
            else "mix:" + "+".join(f"{k / TEXTURE_STEPS:g}*{b}" for k, b in terms)
        )
    return _labelled(part, names, np.asarray(index).ravel())


#: Pattern painters by name: ``(part, rng, palette) -> part``.
PATTERNS: dict[str, Callable[[Part, np.random.Generator, Sequence[str]], Part]] = {
    "stripes": _stripes,
    "checkers": _checkers,
    "patches": _patches,
    "noise": _noise,
    "label": _label,
    "texture": _texture,
}


#: The pattern name of a per-pixel spectral texture (:mod:`spectrinsic.scenes.textures`).
PIXEL_TEXTURE = "pixel-texture"
#: Texels per side of a generated per-pixel texture.
PIXEL_TEXTURE_SIZE = 64


def pixel_texture(
    part: Part, rng: np.random.Generator, dist: MaterialDistribution, sfu: Sequence[str]
) -> Part:
    """*part* under a per-pixel texture: a generated pattern over 2-3 distinct palette spectra
    (one flat spectrum when the distribution holds a single chip)."""
    pattern = TEXTURE_PATTERNS[int(rng.integers(len(TEXTURE_PATTERNS)))]
    palette = tuple(draw_palette(rng, dist, int(rng.integers(2, 4)), sfu))
    seed = int(rng.integers(2**31))
    labels = np.zeros(len(part.faces), np.int64)
    if len(palette) < 2:
        return Part(part.vertices, part.faces, labels, palette)
    return Part(part.vertices, part.faces, labels, palette, (pattern, PIXEL_TEXTURE_SIZE, seed))


def paint(
    part: Part, rng: np.random.Generator, dist: MaterialDistribution, sfu: Sequence[str] = ()
) -> tuple[Part, str]:
    """Paint *part*: one reflectance, or with ``dist.pattern_probability`` a pattern of 2-4.

    With ``dist.texture_fraction`` (drawn first, only when above 0) the part instead takes a
    per-pixel spectral texture over 2-3 reflectances (:data:`PIXEL_TEXTURE`).

    Returns
    -------
    tuple
        The painted part and the pattern's name (``"plain"`` for one spectrum).
    """
    if dist.texture_fraction > 0 and rng.random() < dist.texture_fraction:
        return pixel_texture(part, rng, dist, sfu), PIXEL_TEXTURE
    if rng.random() >= dist.pattern_probability:
        return _labelled(
            part, [draw_reflectance(rng, dist, sfu)], np.zeros(len(part.faces))
        ), "plain"
    names = list(PATTERNS)
    pattern = names[int(rng.integers(len(names)))]
    palette = draw_palette(rng, dist, int(rng.integers(2, 5)), sfu)
    return PATTERNS[pattern](part, rng, palette), pattern
