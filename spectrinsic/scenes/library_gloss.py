"""Glossy variants of the library scenes: ``<scene>-glossy`` (e.g. ``room-living-glossy``).

Each variant is its matte scene (same geometry, views, lights and condition draws) with some
objects' materials replaced by coated (varnished, glazed) or metal versions: every face of a
listed mesh gets a copy of its material with the gloss of :data:`GLOSSY_MESHES`, named
``<spectrum> (<mesh>)``, so other meshes sharing the spectrum stay matte. Object scenes get a
glazed object (smooth coat, η = 1.5) on their matte ground.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .materials import METAL_SPECTRUM
from .model import Material, Scene

__all__ = ["GLOSSY_SUFFIX", "Gloss", "GLOSSY_MESHES", "base_name", "glossy_variant"]

#: Suffix of a glossy variant's name.
GLOSSY_SUFFIX = "-glossy"


@dataclass(frozen=True)
class Gloss:
    """The gloss given to a mesh: ``plastic`` (keeps the base spectrum) or ``conductor``."""

    kind: str = "plastic"
    roughness: float = 0.0
    ior: float = 1.5
    metal: str = ""


#: Per complex scene, mesh name -> gloss; object scenes glaze their object (any non-ground mesh).
GLOSSY_MESHES: dict[str, dict[str, Gloss]] = {
    "room-living": {
        "wall-floor": Gloss(roughness=0.08),
        "table": Gloss(roughness=0.15),
        "cup": Gloss(),
        "vase": Gloss(),
        "box": Gloss("conductor", 0.1, metal="Au"),
    },
    "room-corner": {
        "wall-floor": Gloss(roughness=0.1),
        "cube-red": Gloss(),
        "cube-blue": Gloss("conductor", 0.2, metal="Al"),
        "cube-purple": Gloss("conductor", metal="Cu"),
    },
    "room-studio": {
        "wall-floor": Gloss(roughness=0.2),
        "desk": Gloss(roughness=0.1),
        "cup": Gloss(),
        "vase": Gloss(),
        "shelf": Gloss("conductor", 0.15, metal="Ag"),
    },
}
_GLAZE = Gloss(roughness=0.05)


def base_name(name: str) -> str:
    """The matte scene of *name* (*name* itself if not a glossy variant)."""
    return name.removesuffix(GLOSSY_SUFFIX)


def _material(base: Material, gloss: Gloss, mesh: str) -> Material:
    spectrum = METAL_SPECTRUM if gloss.kind == "conductor" else base.spectrum
    return Material(
        f"{base.name} ({mesh})",
        spectrum,
        kind=gloss.kind,  # type: ignore[arg-type]
        roughness=gloss.roughness,
        ior=gloss.ior,
        metal=gloss.metal,
    )


def glossy_variant(scene: Scene, base: str) -> Scene:
    """*scene* (library scene *base*) with its listed meshes made glossy (module docstring)."""
    table = GLOSSY_MESHES.get(base)
    materials = list(scene.materials)
    meshes = []
    for mesh in scene.meshes:
        gloss = (
            table.get(mesh.name)
            if table is not None
            else (None if mesh.name == "ground" else _GLAZE)
        )
        if gloss is None:
            meshes.append(mesh)
            continue
        fm = np.asarray(mesh.face_materials)
        remap = {}
        for m in np.unique(fm):
            remap[int(m)] = len(materials)
            materials.append(_material(scene.materials[int(m)], gloss, mesh.name))
        new = np.array([remap[int(m)] for m in fm], np.int64)
        meshes.append(replace(mesh, face_materials=new))
    used = sorted({int(m) for mesh in meshes for m in np.unique(mesh.face_materials)})
    index = {old: i for i, old in enumerate(used)}  # drop materials no face uses any more
    meshes = [
        replace(m, face_materials=np.array([index[int(f)] for f in m.face_materials], np.int64))
        for m in meshes
    ]
    return replace(
        scene,
        name=base + GLOSSY_SUFFIX,
        meshes=tuple(meshes),
        materials=tuple(materials[i] for i in used),
        metadata={**scene.metadata, "library": base + GLOSSY_SUFFIX, "glossy_of": base},
    )
