"""Glossy and metallic surfaces in generated scenes: a controllable fraction of the materials.

After a scene is assembled, each of its materials independently becomes, with probability
``metal_fraction``, a metal (a conductor drawn from :data:`METALS`), else with probability
``glossy_fraction`` a coated diffuse (``plastic`` keeping its drawn spectrum, coat index drawn
from ``ior_range``); glossy and metal materials get a GGX roughness α drawn uniformly from
``roughness_range`` (0 = smooth). The draws come from their own seed
(``seed_from_key(scene seed, "gloss")``), so with both fractions 0 (the default) nothing is drawn
and scenes are exactly those of before.

**Glass and mirrors** (off by default): then each material worn only by single-material objects
(semantic class ``object``: vessels, pillars, library models; never walls, floors or furniture)
becomes, with probability ``glass_fraction``, clear smooth glass (``dielectric``, index drawn
from ``ior_range``), else with probability ``mirror_fraction`` a perfect mirror (``conductor``
``none``), from a seed of its own (``seed_from_key(scene seed, "glass")``), so turning them on
changes no other draw, and with both 0 nothing is drawn.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...errors import SceneError
from ...rng import seed_from_key
from ...spectra.conductors import PERFECT_MIRROR
from ..materials import IOR_RANGE, METAL_SPECTRUM
from ..model import Material, Scene

__all__ = ["METALS", "GlossDistribution", "apply_gloss"]

#: Conductors drawn for metal surfaces (Mitsuba's measured η/k tables).
METALS: tuple[str, ...] = ("Ag", "Al", "Au", "Cu", "Cr")


@dataclass(frozen=True)
class GlossDistribution:
    """Fractions of glossy and metal materials (each in [0, 1], summing to at most 1), the
    ranges their roughness α and coat index are drawn from, and the fractions of object
    materials made glass or mirrors (in [0, 1], summing to at most 1; module docstring)."""

    glossy_fraction: float = 0.0
    metal_fraction: float = 0.0
    roughness_range: tuple[float, float] = (0.0, 0.3)
    ior_range: tuple[float, float] = (1.4, 1.6)
    glass_fraction: float = 0.0
    mirror_fraction: float = 0.0

    def __post_init__(self) -> None:
        glass, mirror = float(self.glass_fraction), float(self.mirror_fraction)
        if not (0.0 <= glass <= 1.0 and 0.0 <= mirror <= 1.0 and glass + mirror <= 1.0):
            raise SceneError(
                f"glass fraction {glass}, mirror fraction {mirror}: expected fractions in "
                "[0, 1] summing to <= 1"
            )
        g, m = float(self.glossy_fraction), float(self.metal_fraction)
        lo, hi = (float(v) for v in self.roughness_range)
        i_lo, i_hi = (float(v) for v in self.ior_range)
        if not (0.0 <= g <= 1.0 and 0.0 <= m <= 1.0 and g + m <= 1.0):
            raise SceneError(
                f"glossy fraction {g}, metallic fraction {m}: expected fractions in [0, 1] summing to <= 1"
            )
        if not 0.0 <= lo <= hi <= 1.0:
            raise SceneError(
                f"roughness range ({lo}, {hi}): expected 0 <= low <= high <= 1 (GGX alpha)"
            )
        if not IOR_RANGE[0] < i_lo <= i_hi <= IOR_RANGE[1]:
            raise SceneError(
                f"coat ior range ({i_lo}, {i_hi}): expected {IOR_RANGE[0]:g} < low <= high <= {IOR_RANGE[1]:g}"
            )

    @property
    def active(self) -> bool:
        return self.glossy_fraction > 0.0 or self.metal_fraction > 0.0 or self.glass_active

    @property
    def glass_active(self) -> bool:
        return self.glass_fraction > 0.0 or self.mirror_fraction > 0.0


def _draw(material: Material, dist: GlossDistribution, rng: np.random.Generator) -> Material:
    """One material's draw; the same four numbers are drawn whatever the outcome, so each
    material's draw does not depend on the others'."""
    u, rough, ior = rng.random(), rng.uniform(*dist.roughness_range), rng.uniform(*dist.ior_range)
    metal = METALS[int(rng.integers(len(METALS)))]
    if u < dist.metal_fraction:
        return Material(
            material.name, METAL_SPECTRUM, kind="conductor", roughness=float(rough), metal=metal
        )
    if u < dist.metal_fraction + dist.glossy_fraction:
        return Material(
            material.name, material.spectrum, kind="plastic", roughness=float(rough), ior=float(ior)
        )
    return material


def _object_materials(scene: Scene) -> list[int]:
    """Indices of the materials worn only by untextured single-material ``object`` meshes."""
    objects: set[int] = set()
    others: set[int] = set()
    for mesh in scene.meshes:
        used = set(np.unique(mesh.face_materials).tolist())
        single = len(used) == 1 and mesh.texture is None
        (objects if mesh.semantic == "object" and single else others).update(used)
    return sorted(objects - others)


def _glass_or_mirror(
    material: Material, dist: GlossDistribution, rng: np.random.Generator
) -> Material:
    """One object material's glass-or-mirror draw (two numbers whatever the outcome)."""
    u, ior = rng.random(), rng.uniform(*dist.ior_range)
    if u < dist.glass_fraction:
        return Material(material.name, METAL_SPECTRUM, kind="dielectric", ior=float(ior))
    if u < dist.glass_fraction + dist.mirror_fraction:
        return Material(material.name, METAL_SPECTRUM, kind="conductor", metal=PERFECT_MIRROR)
    return material


def _apply_glass(
    materials: list[Material], scene: Scene, dist: GlossDistribution, seed: int
) -> dict:
    """Make some object materials (in place) glass or mirrors; their counts."""
    rng = np.random.default_rng(seed_from_key(seed, "glass"))
    for i in _object_materials(scene):
        materials[i] = _glass_or_mirror(materials[i], dist, rng)
    return {
        "glass_materials": sum(m.transmissive for m in materials),
        "mirror_materials": sum(m.metal == PERFECT_MIRROR for m in materials),
    }


def apply_gloss(scene: Scene, dist: GlossDistribution, seed: int) -> Scene:
    """*scene* with some materials made glossy or metal (module docstring); *scene* itself when
    the distribution is inactive. Records the counts in the metadata."""
    if not dist.active:
        return scene
    rng = np.random.default_rng(seed_from_key(seed, "gloss"))
    materials = [_draw(m, dist, rng) for m in scene.materials]
    glass = _apply_glass(materials, scene, dist, seed) if dist.glass_active else {}
    counts = {
        "glossy_materials": sum(m.kind == "plastic" for m in materials),
        "metal_materials": sum(m.kind == "conductor" for m in materials),
    } | glass
    return replace(scene, materials=tuple(materials), metadata={**scene.metadata, **counts})
