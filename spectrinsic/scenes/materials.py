"""Materials in scene files: the one parser and writer of a YAML ``materials:`` entry, and the
check of a material's gloss parameters.

A material is a spectrum name (Lambertian, as before) or a mapping::

    materials:
      wall: "munsell:5Y 8/2"                         # Lambertian
      cup: {kind: plastic, spectrum: "munsell:5R 4/14", ior: 1.5, roughness: 0.1}
      lamp: {kind: conductor, metal: Au, roughness: 0.05}
      mirror: {kind: conductor, metal: none}            # perfect mirror, F = 1
      vase: {kind: dielectric, ior: 1.5, roughness: 0}  # clear glass, solid
      pane: {kind: thindielectric, ior: 1.5}            # clear glass, a thin sheet
      bottle: {kind: dielectric, transmittance: "rgb:0.2,0.6,0.3"}  # tinted glass
      gem: {kind: dielectric, specular_reflectance: "rgb:0.9,0.3,0.3"}  # tinted reflections
      foil: {kind: conductor, metal: none, specular_reflectance: "rgb:0.9,0.6,0.2"}  # coloured mirror

``plastic`` is a diffuse base under a dielectric coat of index ``ior`` (Mitsuba ``plastic``,
or ``roughplastic`` when ``roughness`` > 0); ``conductor`` is a metal with Mitsuba's measured
η/k of ``metal`` (``conductor`` / ``roughconductor``; ``none`` is Mitsuba's perfect mirror) and
no diffuse lobe (spectrum ``flat:0``). ``dielectric`` is a clear glass solid of index ``ior``
relative to the outside (Mitsuba ``dielectric``, or ``roughdielectric`` with GGX when
``roughness`` > 0); ``thindielectric`` a smooth thin pane (Mitsuba ``thindielectric``); glass has
no diffuse lobe either and a constant ``ior`` (no dispersion). Glass is clear unless given a
``transmittance``: a spectrum name (as ``spectrum``, values in [0, 1]) that multiplies each
transmission through the surface, not its reflections (Mitsuba's ``specular_transmittance``:
twice through a solid, entering and leaving; once through a pane), and a
``specular_reflectance`` likewise multiplies each reflection off it (Mitsuba's parameter of
that name; a Blender Glass BSDF's Color is both). A ``conductor`` takes a
``specular_reflectance`` too (its Fresnel times the tint; ``metal: none`` a coloured mirror).
``roughness`` is the GGX α in [0, 1] (0 = smooth); ``ior`` lies in (1, 3].

A ``textured`` material is a spectral texture (:mod:`spectrinsic.scenes.textures`): per texel a
convex mix of 2–4 ``basis`` reflectances, from a generated ``pattern`` (``rings``, ``weave``,
``noise``) of ``size`` × ``size`` texels and a ``seed``, or from explicit ``weights`` (an
``h × w × B`` nested list, each texel non-negative and summing to 1)::

      table: {kind: textured, basis: ["munsell:10YR 6/6", "munsell:5YR 3/4"], pattern: rings,
              size: 64, seed: 3}

Its basis spectra become diffuse materials ``table[0]``, ``table[1]``, ...; a mesh taking
``material: table`` carries the texture over all its faces.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import SpectralDataError, did_you_mean
from ..spectra.conductors import check_conductor
from .model import GLASS_TINTS, MATERIAL_KINDS, Material
from .textures import (
    BASIS_MAX,
    PATTERNS,
    TEXTURE_MAX,
    Texture,
    basis_name,
    make_texture,
    weights_problem,
)

__all__ = [
    "METAL_SPECTRUM",
    "IOR_RANGE",
    "TEXTURED",
    "TexturedMaterial",
    "material_problem",
    "parse_material",
    "material_entry",
    "textured_entry",
]

#: The diffuse spectrum of a conductor: no diffuse lobe.
METAL_SPECTRUM = "flat:0"
#: Allowed coat indices of refraction (exclusive, inclusive).
IOR_RANGE = (1.0, 3.0)
#: The kind of a spectrally textured material in scene files.
TEXTURED = "textured"
_TEXTURED_KEYS = ("kind", "basis", "pattern", "size", "seed", "weights")
_KEYS = {
    "diffuse": ("kind", "spectrum"),
    "plastic": ("kind", "spectrum", "ior", "roughness"),
    "conductor": ("kind", "metal", "roughness", "specular_reflectance"),
    "dielectric": ("kind", "ior", "roughness", *GLASS_TINTS),
    "thindielectric": ("kind", "ior", *GLASS_TINTS),
}


@dataclass(frozen=True, eq=False)
class TexturedMaterial:
    """A parsed ``textured`` entry: its basis materials and its texture, whose ``basis`` holds
    positions within :attr:`materials` (the scene reader offsets them)."""

    materials: tuple[Material, ...]
    texture: Texture


def _number(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)


def material_problem(m: Material) -> str | None:
    """What is wrong with *m*'s gloss parameters (one phrase), or ``None``."""
    if m.kind not in MATERIAL_KINDS:
        return f"kind {m.kind!r}: expected one of {', '.join(MATERIAL_KINDS)}" + did_you_mean(
            str(m.kind), MATERIAL_KINDS
        )
    if not _number(m.roughness) or not 0.0 <= m.roughness <= 1.0:
        return f"roughness {m.roughness!r}: expected a GGX alpha in [0, 1]"
    if not _number(m.ior) or not IOR_RANGE[0] < m.ior <= IOR_RANGE[1]:
        return f"ior {m.ior!r}: expected an index of refraction in ({IOR_RANGE[0]:g}, {IOR_RANGE[1]:g}]"
    if m.non_diffuse and m.spectrum != METAL_SPECTRUM:
        return (
            f"a {m.kind} has no diffuse spectrum (expected {METAL_SPECTRUM!r}, got {m.spectrum!r})"
        )
    if m.kind == "thindielectric" and m.roughness != 0.0:
        return f"roughness {m.roughness!r}: a thindielectric is smooth (Mitsuba has no rough one)"
    for key in GLASS_TINTS:
        tint = getattr(m, key)
        if not isinstance(tint, str):
            return f"{key} {tint!r}: expected a spectrum name"
        allowed = m.transmissive or (m.kind == "conductor" and key == "specular_reflectance")
        if tint and not allowed:
            where = "glass and conductors" if key == "specular_reflectance" else "glass"
            return f"{key} {tint!r} given for a {m.kind} material (only for {where})"
    if m.kind == "conductor":
        try:
            check_conductor(m.metal)
        except SpectralDataError as exc:
            return str(exc)
    elif m.metal:
        return f"metal {m.metal!r} given for a {m.kind} material (only for kind conductor)"
    return None


def _whole(value: Any, lo: int, hi: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and lo <= value <= hi


def _parse_textured(name: str, value: dict) -> TexturedMaterial | str:
    unknown = [k for k in value if k not in _TEXTURED_KEYS]
    if unknown:
        return f"unknown key {unknown[0]!r} for kind textured; expected {', '.join(_TEXTURED_KEYS)}"
    basis = value.get("basis")
    if not isinstance(basis, list) or not 2 <= len(basis) <= BASIS_MAX:
        return f"basis: expected a list of 2 to {BASIS_MAX} spectrum names, got {basis!r}"
    if not all(isinstance(b, str) and b.strip() for b in basis):
        return f"basis: expected non-empty spectrum names, got {basis!r}"
    mats = tuple(Material(basis_name(name, b), s) for b, s in enumerate(basis))
    where = tuple(range(len(basis)))
    if ("pattern" in value) == ("weights" in value):
        return "give exactly one of 'pattern' (with size and seed) or 'weights'"
    if "weights" in value:
        if any(k in value for k in ("size", "seed")):
            return "size and seed go with a pattern, not with explicit weights"
        try:
            w = np.asarray(value["weights"], dtype=np.float64)
        except (TypeError, ValueError):
            return "weights: expected an h x w x B nested list of numbers"
        problem = weights_problem(w)
        if problem is None and w.shape[2] != len(basis):
            problem = f"weights have {w.shape[2]} per texel for {len(basis)} basis spectra"
        return problem or TexturedMaterial(mats, Texture(name, where, w))
    pattern: Any = value["pattern"]
    size: Any = value.get("size")
    seed: Any = value.get("seed", 0)
    if pattern not in PATTERNS:
        return f"pattern {pattern!r}: expected one of {', '.join(PATTERNS)}" + did_you_mean(
            str(pattern), PATTERNS
        )
    if not _whole(size, 1, TEXTURE_MAX):
        return f"size {size!r}: expected a whole number of texels per side, 1 to {TEXTURE_MAX}"
    if not _whole(seed, 0, 2**63 - 1):
        return f"seed {seed!r}: expected a non-negative whole number"
    return TexturedMaterial(mats, make_texture(name, where, pattern, size, seed))


def parse_material(name: str, value: Any) -> Material | TexturedMaterial | str:
    """The :class:`Material` (or :class:`TexturedMaterial`) of one YAML entry (module
    docstring), or a one-phrase problem."""
    if isinstance(value, str):
        return (
            Material(name=name, spectrum=value)
            if value.strip()
            else "expected a non-empty spectrum name"
        )
    if not isinstance(value, dict):
        return f"expected a spectrum name or a mapping with 'kind', got {value!r}"
    kind = value.get("kind", "diffuse")
    if kind == TEXTURED:
        return _parse_textured(name, value)
    if kind not in _KEYS:
        kinds = (*MATERIAL_KINDS, TEXTURED)
        return f"kind {kind!r}: expected one of {', '.join(kinds)}" + did_you_mean(str(kind), kinds)
    unknown = [k for k in value if k not in _KEYS[kind]]
    if unknown:
        return f"unknown key {unknown[0]!r} for kind {kind}; expected {', '.join(_KEYS[kind])}"
    need = {"conductor": "metal", "diffuse": "spectrum", "plastic": "spectrum"}.get(kind)
    if need and (not isinstance(value.get(need), str) or not value[need].strip()):
        return f"kind {kind} needs a non-empty '{need}'"
    for key in ("ior", "roughness"):
        if key in value and not _number(value[key]):
            return f"{key}: expected a number, got {value[key]!r}"
    for key in GLASS_TINTS:
        tint = value.get(key, "")
        if key in value and (not isinstance(tint, str) or not tint.strip()):
            return f"{key}: expected a non-empty spectrum name, got {tint!r}"
    m = Material(
        name=name,
        spectrum=value["spectrum"] if "spectrum" in _KEYS[kind] else METAL_SPECTRUM,
        kind=kind,
        roughness=float(value.get("roughness", 0.0)),
        ior=float(value.get("ior", 1.5)),
        metal=value.get("metal", ""),
        transmittance=value.get("transmittance", ""),
        specular_reflectance=value.get("specular_reflectance", ""),
    )
    return material_problem(m) or m


def material_entry(m: Material) -> str | dict[str, Any]:
    """The YAML entry of *m*: its spectrum name if Lambertian, else a mapping."""
    if m.kind == "diffuse":
        return m.spectrum
    entry: dict[str, Any] = {"kind": m.kind}
    if m.kind == "conductor":
        entry["metal"] = m.metal
    elif m.kind == "plastic":
        entry["spectrum"] = m.spectrum
    if "ior" in _KEYS[m.kind]:
        entry["ior"] = float(m.ior)
    if "roughness" in _KEYS[m.kind]:
        entry["roughness"] = float(m.roughness)
    entry |= {key: getattr(m, key) for key in GLASS_TINTS if getattr(m, key)}
    return entry


def textured_entry(texture: Texture, spectra: list[str]) -> dict[str, Any]:
    """The YAML entry of *texture* over basis *spectra*: its recipe, or its explicit weights."""
    entry: dict[str, Any] = {"kind": TEXTURED, "basis": list(spectra)}
    if texture.pattern:
        return entry | {
            "pattern": texture.pattern,
            "size": int(texture.size),
            "seed": int(texture.seed),
        }
    return entry | {"weights": np.asarray(texture.weights, np.float64).tolist()}
