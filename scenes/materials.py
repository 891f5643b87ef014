"""Materials in scene files: the one parser and writer of a YAML ``materials:`` entry, and the
check of a material's gloss parameters.

A material is a spectrum name (Lambertian, as before) or a mapping::

    materials:
      wall: "munsell:5Y 8/2"                         # Lambertian
      cup: {kind: plastic, spectrum: "munsell:5R 4/14", ior: 1.5, roughness: 0.1}
      lamp: {kind: conductor, metal: Au, roughness: 0.05}

``plastic`` is a diffuse base under a dielectric coat of index ``ior`` (Mitsuba ``plastic``,
or ``roughplastic`` when ``roughness`` > 0); ``conductor`` is a metal with Mitsuba's measured
η/k of ``metal`` (``conductor`` / ``roughconductor``) and no diffuse lobe (spectrum
``flat:0``). ``roughness`` is the GGX α in [0, 1] (0 = smooth); ``ior`` lies in (1, 3].
"""

from __future__ import annotations

import math
from typing import Any

from spectrinsic.errors import SpectralDataError, did_you_mean
from spectrinsic.scenes.model import MATERIAL_KINDS, Material
from spectrinsic.spectra.conductors import check_conductor

__all__ = ["METAL_SPECTRUM", "IOR_RANGE", "material_problem", "parse_material", "material_entry"]

#: The diffuse spectrum of a conductor: no diffuse lobe.
METAL_SPECTRUM = "flat:0"
#: Allowed coat indices of refraction (exclusive, inclusive).
IOR_RANGE = (1.0, 3.0)
_KEYS = {
    "diffuse": ("kind", "spectrum"),
    "plastic": ("kind", "spectrum", "ior", "roughness"),
    "conductor": ("kind", "metal", "roughness"),
}


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
    if m.kind == "conductor":
        if m.spectrum != METAL_SPECTRUM:
            return f"a conductor has no diffuse spectrum (expected {METAL_SPECTRUM!r}, got {m.spectrum!r})"
        try:
            check_conductor(m.metal)
        except SpectralDataError as exc:
            return str(exc)
    elif m.metal:
        return f"metal {m.metal!r} given for a {m.kind} material (only for kind conductor)"
    return None


def parse_material(name: str, value: Any) -> Material | str:
    """The :class:`Material` of one YAML entry (module docstring), or a one-phrase problem."""
    if isinstance(value, str):
        return (
            Material(name=name, spectrum=value)
            if value.strip()
            else "expected a non-empty spectrum name"
        )
    if not isinstance(value, dict):
        return f"expected a spectrum name or a mapping with 'kind', got {value!r}"
    kind = value.get("kind", "diffuse")
    if kind not in _KEYS:
        return f"kind {kind!r}: expected one of {', '.join(MATERIAL_KINDS)}" + did_you_mean(
            str(kind), MATERIAL_KINDS
        )
    unknown = [k for k in value if k not in _KEYS[kind]]
    if unknown:
        return f"unknown key {unknown[0]!r} for kind {kind}; expected {', '.join(_KEYS[kind])}"
    need = "metal" if kind == "conductor" else "spectrum"
    if not isinstance(value.get(need), str) or not value[need].strip():
        return f"kind {kind} needs a non-empty '{need}'"
    for key in ("ior", "roughness"):
        if key in value and not _number(value[key]):
            return f"{key}: expected a number, got {value[key]!r}"
    m = Material(
        name=name,
        spectrum=METAL_SPECTRUM if kind == "conductor" else value["spectrum"],
        kind=kind,
        roughness=float(value.get("roughness", 0.0)),
        ior=float(value.get("ior", 1.5)),
        metal=value.get("metal", ""),
    )
    return material_problem(m) or m


def material_entry(m: Material) -> str | dict[str, Any]:
    """The YAML entry of *m*: its spectrum name if Lambertian, else a mapping."""
    if m.kind == "diffuse":
        return m.spectrum
    entry: dict[str, Any] = {"kind": m.kind}
    if m.kind == "conductor":
        entry["metal"] = m.metal
    else:
        entry |= {"spectrum": m.spectrum, "ior": float(m.ior)}
    entry["roughness"] = float(m.roughness)
    return entry
