"""The one translation of a :class:`~spectrinsic.scenes.model.Scene` into a Mitsuba scene dict.

Geometry, lights and camera come from the scene; colours come from the caller as Mitsuba
spectrum dicts (:func:`rgb_spectrum` for the channel values of a diagonal pass,
:func:`regular_spectrum` for the spectral variant), so the same translation serves every pass.

Naming, which :mod:`spectrinsic.render.passes` relies on to update parameters between passes:

* each mesh is split by material into shapes ``surf_<mesh>_<material>``, each with its own
  two-sided BSDF: Lambertian (``<id>.bsdf.brdf_0.reflectance``), or for a glossy material
  (:func:`material_bsdf`) Mitsuba's ``plastic``/``roughplastic`` (the reflectance is the
  ``diffuse_reflectance`` under the coat) or ``conductor``/``roughconductor``;
* light ``i`` is ``light_<i>``; an area light is a rectangle shape with an ``area`` emitter and a
  black two-sided BSDF, so it occludes and reflects nothing;
* an environment map's three channel lights are **one** Mitsuba ``envmap`` keyed by the first
  of them given an emission (:func:`envmap_entry`); Mitsuba takes one environment emitter per
  scene, so only the first map given an emission is loaded (the band path evaluates the
  others itself, :mod:`spectrinsic.render.band_path.kernel`).

Two-sided BSDFs make face winding irrelevant (a room's walls render from inside whichever way
they were wound). The triangles, their smoothed normals and texture coordinates come from
:func:`spectrinsic.render.base.geometry.prepare_geometry`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import SceneError
from ...scenes.envmaps import verified_map
from ...scenes.model import Light, Material, Scene, unknown_light_kind
from .geometry import SurfaceGeometry, prepare_geometry
from .plugins import black_bsdf
from .surface_maps import wrap_bsdf
from .textures import textured_bsdf
from .variants import import_mitsuba

__all__ = [
    "Surface",
    "surfaces",
    "light_key",
    "reflectance_key",
    "material_bsdf",
    "emission_key",
    "envmap_entry",
    "envmap_to_world",
    "scene_to_mitsuba",
]

#: Emitter parameter holding the spectrum of each kind of
#: :data:`spectrinsic.scenes.model.LIGHT_KINDS` in Mitsuba (the meaning of ``Light.power``).
_EMISSION_PARAM = {
    "point": "intensity",
    "spot": "intensity",
    "directional": "irradiance",
    "area": "radiance",
    "sky": "radiance",
    "sphere": "radiance",
    "envmap": "scale",
}
#: Light kinds that are shapes carrying an ``area`` emitter.
_SHAPE_LIGHTS = ("area", "sphere")


@dataclass(frozen=True)
class Surface:
    """A Mitsuba shape carrying one BSDF: a mesh's faces of one material, or an area light.

    Attributes
    ----------
    key
        Shape id in the Mitsuba dict.
    mesh
        Index into ``scene.meshes``, or -1 for an area light.
    material
        Index into ``scene.materials``, or -1 for an area light.
    light
        Index into ``scene.lights`` for an area light, else -1.
    """

    key: str
    mesh: int
    material: int
    light: int = -1


def light_key(index: int) -> str:
    """Id of light *index* in the Mitsuba dict."""
    return f"light_{index}"


def surfaces(scene: Scene) -> list[Surface]:
    """Every BSDF-carrying shape of *scene*'s Mitsuba dict, in a stable order."""
    out = []
    for i, mesh in enumerate(scene.meshes):
        for m in np.unique(np.asarray(mesh.face_materials)):
            out.append(Surface(f"surf_{i}_{int(m)}", i, int(m)))
    for j, light in enumerate(scene.lights):
        if light.kind in _SHAPE_LIGHTS:
            out.append(Surface(light_key(j), -1, -1, j))
    return out


def reflectance_key(surface: Surface, *, spectral: bool) -> str:
    """``mi.traverse`` key of a surface's reflectance values."""
    return f"{surface.key}.bsdf.brdf_0.reflectance." + ("values" if spectral else "value")


def emission_key(scene: Scene, index: int, *, spectral: bool) -> str:
    """``mi.traverse`` key of light *index*'s emitted spectrum."""
    light = scene.lights[index]
    prefix = (
        f"{light_key(index)}.emitter." if light.kind in _SHAPE_LIGHTS else f"{light_key(index)}."
    )
    return prefix + _EMISSION_PARAM[light.kind] + (".values" if spectral else ".value")


def _mitsuba_mesh(mi: Any, part: SurfaceGeometry, bsdf: Mapping) -> Any:
    """An ``mi.Mesh`` with unshared vertices (one per face corner), the given normals and,
    on a textured surface, texture coordinates."""
    corners, n_faces = part.corners, part.corners.shape[0]
    props = mi.Properties()
    props["bsdf"] = mi.load_dict(dict(bsdf))
    mesh = mi.Mesh(
        part.key,
        vertex_count=3 * n_faces,
        face_count=n_faces,
        has_vertex_normals=True,
        has_vertex_texcoords=part.uv is not None,
        props=props,
    )
    params = mi.traverse(mesh)
    arrays = [
        ("vertex_positions", corners.reshape(-1).astype(np.float32)),
        ("faces", np.arange(3 * n_faces, dtype=np.uint32)),
        ("vertex_normals", part.normals.reshape(-1).astype(np.float32)),
    ]
    if part.uv is not None:
        arrays.append(("vertex_texcoords", part.uv.reshape(-1).astype(np.float32)))
    for key, array in arrays:
        params[key] = type(params[key])(array)
    params.update()
    return mesh


def material_bsdf(
    material: Material,
    reflectance: Mapping,
    *,
    white_metal: bool = False,
    tints: Mapping[str, Mapping] | None = None,
) -> dict[str, Any]:
    """The two-sided Mitsuba BSDF of *material* with diffuse *reflectance*.

    ``plastic``: Mitsuba's ``plastic`` (smooth) or ``roughplastic`` (GGX, α = roughness) with
    the linear diffuse term (``nonlinear: false``, so the diffuse lobe is proportional to the
    base reflectance) and ``int_ior`` = the coat's index over air. ``conductor``: Mitsuba's
    ``conductor``/``roughconductor`` with its measured η/k of ``material.metal``, or with
    *white_metal* a perfect mirror (``material: none``, F = 1) whose Fresnel factor the band
    integrator applies per band. Glass: Mitsuba's ``(rough)dielectric``/``thindielectric`` of
    index ``ior`` over air's 1, not in a ``twosided``, with *tints* (``{Mitsuba parameter:
    spectrum dict}``, ``specular_transmittance`` and ``specular_reflectance``) where given
    (tinted glass; the band path loads it clear and applies the tints per band). Else
    Lambertian.
    """
    if material.kind == "diffuse":
        return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": dict(reflectance)}}
    rough = material.roughness > 0.0
    if material.transmissive:  # a thindielectric is always smooth (materials.py)
        glass = {"type": material.kind, "int_ior": float(material.ior), "ext_ior": 1.0}
        ggx = {"type": "roughdielectric", "distribution": "ggx", "alpha": material.roughness}
        tint = {key: dict(value) for key, value in (tints or {}).items()}
        return glass | (ggx if rough else {}) | tint
    bsdf: dict[str, Any]
    if material.kind == "plastic":
        bsdf = {
            "type": "roughplastic" if rough else "plastic",
            "diffuse_reflectance": dict(reflectance),
            "int_ior": float(material.ior),
            "ext_ior": 1.0,
            "nonlinear": False,
        }
    else:
        bsdf = {
            "type": "roughconductor" if rough else "conductor",
            "material": "none" if white_metal else material.metal,
        } | {key: dict(value) for key, value in (tints or {}).items()}
    if rough:
        bsdf |= {"distribution": "ggx", "alpha": float(material.roughness)}
    return {"type": "twosided", "bsdf": bsdf}


def _surface_bsdf(
    scene: Scene,
    part: SurfaceGeometry,
    materials: Sequence[Mapping],
    white_metal: bool,
    transmittances: Sequence[Mapping[str, Mapping] | None],
) -> dict[str, Any]:
    """The BSDF of one surface: its material's, or on a textured mesh the texel-weighted mix of
    its basis materials (a mix of equal reflectances, such as the band path's white load, is
    that reflectance), wrapped by the mesh's mask and bump or normal map
    (:func:`~spectrinsic.render.base.surface_maps.wrap_bsdf`)."""
    mesh = scene.meshes[part.mesh] if part.mesh >= 0 else None
    texture = None if mesh is None else mesh.texture
    bsdf = material_bsdf(
        scene.materials[part.material],
        materials[part.material],
        white_metal=white_metal,
        tints=transmittances[part.material] if transmittances else None,
    )
    if texture is not None:
        basis = [materials[b] for b in texture.basis]
        if any(dict(b) != dict(basis[0]) for b in basis[1:]):
            bsdf = textured_bsdf(import_mitsuba(), texture, basis)
    if mesh is not None and mesh.maps is not None:  # cut-outs and perturbed normals
        bsdf = wrap_bsdf(import_mitsuba(), mesh.maps, bsdf)
    return bsdf


def _look_at(mi: Any, origin: Sequence[float], direction: Sequence[float], what: str) -> Any:
    d = np.asarray(direction, float)
    if not np.linalg.norm(d) > 0:
        raise SceneError(f"{what}: direction {tuple(direction)} has zero length")
    d = d / np.linalg.norm(d)
    up = np.array([0.0, 0.0, 1.0]) if abs(d[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
    o = np.asarray(origin, float)
    return mi.ScalarTransform4f().look_at(
        origin=o.tolist(), target=(o + d).tolist(), up=up.tolist()
    )


def envmap_to_world(light: Light) -> np.ndarray:
    """The 4 × 4 ``to_world`` of environment-map light *light*: its rotation."""
    matrix = np.eye(4)
    matrix[:3, :3] = np.asarray(light.rotation, float).reshape(3, 3)
    return matrix


def envmap_entry(mi: Any, light: Light) -> dict[str, Any]:
    """The Mitsuba ``envmap`` of environment-map light *light*: its file's RGB data at unit
    scale (exact in RGB variants, ``docs/envmap_design.md`` fact 2; the channel lights' powers
    are applied outside Mitsuba), rotated by the map's ``to_world``."""
    return {
        "type": "envmap",
        "scale": 1.0,
        "to_world": mi.ScalarTransform4f(envmap_to_world(light).tolist()),
        "filename": verified_map(light),
    }


def _light(mi: Any, light: Light, emission: Mapping | None, what: str) -> dict[str, Any] | None:
    """The Mitsuba entry of *light* emitting *emission*; ``None`` leaves it out (the shape of
    an area or sphere light stays, black)."""
    if light.kind in _SHAPE_LIGHTS:
        return _shape_light(mi, light, emission, what)
    if light.kind not in _EMISSION_PARAM:
        raise SceneError(f"{what}: {unknown_light_kind(light.kind)}")
    if emission is None:
        return None
    if light.kind == "envmap":
        return envmap_entry(mi, light)
    if light.kind == "point":
        return {
            "type": "point",
            "position": list(map(float, light.position)),
            "intensity": dict(emission),
        }
    if light.kind == "spot":
        return {
            "type": "spot",
            "to_world": _look_at(mi, light.position, light.direction, what),
            "cutoff_angle": float(light.cutoff_deg),
            "intensity": dict(emission),
        }
    if light.kind == "directional":
        return {
            "type": "directional",
            "direction": list(map(float, light.direction)),
            "irradiance": dict(emission),
        }
    return {"type": "constant", "radiance": dict(emission)}  # sky


def _shape_light(mi: Any, light: Light, emission: Mapping | None, what: str) -> dict[str, Any]:
    w, h = (float(s) for s in light.size)
    shape: dict[str, Any] = (
        {
            "type": "rectangle",
            "to_world": _look_at(mi, light.position, light.direction, what)
            @ mi.ScalarTransform4f().scale([w / 2, h / 2, 1.0]),
        }
        if light.kind == "area"
        else {
            "type": "sphere",
            "center": list(map(float, light.position)),
            "radius": float(light.radius),
        }
    )
    # an instance, not a dict: load_dict merges identical dicts into one shared BSDF,
    # and every surface needs its own for the per-surface coverage passes
    shape["bsdf"] = mi.load_dict(black_bsdf())
    if emission is not None:
        shape["emitter"] = {"type": "area", "radiance": dict(emission)}
    return shape


def _camera(mi: Any, scene: Scene, film: Mapping, sample_count: int) -> dict[str, Any]:
    cam = scene.camera
    return {
        "type": "perspective",
        "fov": float(cam.fov_deg),
        "fov_axis": "x",
        "to_world": mi.ScalarTransform4f().look_at(
            origin=list(map(float, cam.origin)),
            target=list(map(float, cam.target)),
            up=list(map(float, cam.up)),
        ),
        "film": dict(film),
        "sampler": {"type": "independent", "sample_count": int(sample_count)},
    }


def scene_to_mitsuba(
    scene: Scene,
    *,
    materials: Sequence[Mapping],
    lights: Sequence[Mapping | None],
    film: Mapping,
    integrator: Mapping,
    sample_count: int,
    geometry: Sequence[SurfaceGeometry] | None = None,
    white_metal: bool = False,
    transmittances: Sequence[Mapping[str, Mapping] | None] = (),
) -> dict[str, Any]:
    """Translate *scene* into a dict for ``mitsuba.load_dict``.

    Call inside :func:`spectrinsic.render.base.variants.variant_scope`: meshes become ``mi.Mesh``
    objects of the active variant.

    Parameters
    ----------
    materials
        One Mitsuba spectrum dict per ``scene.materials`` entry: its reflectance.
    lights
        One Mitsuba spectrum dict per ``scene.lights`` entry: its emission (already scaled by
        the light's power), or ``None`` to leave that light out (an area light's rectangle then
        stays, black, so per-light renders sum to the full render).
    film, integrator
        Mitsuba dicts (:func:`hdr_film`, :func:`spectral_film`, :func:`path_integrator`,
        :func:`aov_integrator`).
    sample_count
        Samples per pixel of the sensor's sampler.
    geometry
        :func:`prepare_geometry` of *scene*, if already computed.
    white_metal
        Metals as perfect mirrors (:func:`material_bsdf`), for the band integrator.
    transmittances
        One ``{Mitsuba parameter: spectrum dict}`` (or ``None``) per ``scene.materials``
        entry: a tinted glass's ``specular_transmittance`` and ``specular_reflectance``; empty
        (the default): every glass clear, as the band integrator loads it.
    """
    mi = import_mitsuba()
    if transmittances and len(transmittances) != len(scene.materials):
        raise SceneError(
            f"scene {scene.name!r}: got {len(transmittances)} transmittances for "
            f"{len(scene.materials)} materials"
        )
    if len(materials) != len(scene.materials) or len(lights) != len(scene.lights):
        raise SceneError(
            f"scene {scene.name!r}: got {len(materials)} material and {len(lights)} light colours for "
            f"{len(scene.materials)} materials and {len(scene.lights)} lights"
        )
    out: dict[str, Any] = {
        "type": "scene",
        "integrator": dict(integrator),
        "sensor": _camera(mi, scene, film, sample_count),
    }
    for part in prepare_geometry(scene) if geometry is None else geometry:
        bsdf = _surface_bsdf(scene, part, materials, white_metal, transmittances)
        out[part.key] = _mitsuba_mesh(mi, part, bsdf)
    loaded_map = False  # Mitsuba takes one environment emitter: the first map given one
    for j, (light, emission) in enumerate(zip(scene.lights, lights, strict=True)):
        if light.kind == "envmap" and emission is not None:
            if loaded_map:
                continue
            loaded_map = True
        entry = _light(mi, light, emission, f"scene {scene.name!r} light {j} ({light.name})")
        if entry is not None:
            out[light_key(j)] = entry
    return out
