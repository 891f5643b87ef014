"""Import scenes from Blender ``.blend`` files (optional extra ``blender``: ``bpy``).

:func:`load_blend` opens a ``.blend`` with Python auto-execution disabled (the file's scripts,
registered text blocks and Python drivers do not run, so untrusted files are safe to read) and
converts, in world space:

- every visible mesh-like object (mesh, curve, surface, metaball, text) with its modifiers
  applied, triangulated, each face keeping its material slot;
- the scene camera (pose, horizontal field of view from lens, sensor and sensor fit, and the
  render resolution), which must exist and be a perspective camera;
- point, spot, area and sun lights. Blender's light colour is ignored: each light's spectrum is
  its custom property ``"spectrum"`` (on the object or the light data), else *light_spectrum*.
  Powers are converted from Blender's watts: point and spot radiant intensity ``P / 4π``, area
  radiance ``P / (π A)`` (one-sided Lambertian), sun irradiance = strength;
- the World: a background colour as a ``sky``, an Environment Texture as an environment map
  (:mod:`~spectrinsic.scenes.blender_world`; *approximate*: what it cannot read exactly).

Each material becomes a material named after the Blender material, with its reflectance
spectrum chosen by, in order: the *materials* mapping passed in, the material's custom property
``"spectrum"``, or the material's own name (name a material ``"munsell:5R 4/14"`` and nothing
else is needed). A Principled BSDF node sets the gloss (:func:`principled_gloss`): Metallic
≥ 0.5 makes a metal (``conductor``, η/k of the custom property ``"metal"``, default ``Al``; no
spectrum needed), else Roughness < 0.5 a coated diffuse (``plastic``, the node's IOR); GGX α is
Roughness² (Blender's convention); Transmission 1 or a Glass BSDF is glass, the Principled's
tinted by its Base Color, the Glass BSDF's reflection and transmission by its Color
(:mod:`~spectrinsic.scenes.blender_gloss`). Everything else of the node (coat, sheen,
subsurface, emission, textures) is ignored; other materials are Lambertian.

With ``colours_from_asset=True`` (the default; ``--no-colours-from-asset`` turns it off), a
material that the mapping, its custom property and its name leave without a spectrum takes the
Principled node's Base Color (linear Rec. 709, from the file's working space; alpha ignored) as
the reflectance ``rgb:R,G,B`` (:mod:`spectrinsic.spectra.user_spectra`, Mallett & Yuksel 2019);
a colour outside [0, 1] is refused when validated, not clipped, and a Base Color fed by a node
is not read, so that material still needs a spectrum, unless the node is an Image Texture on a
UV map: that image becomes an exact spectral texture (:mod:`spectrinsic.scenes.blender_colours`;
the object must hold that material alone). Without the option such a material is an error.

Opening a file replaces the data of the running ``bpy`` session (Blender has one global state).
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MissingDependencyError, SceneError, SpectrinsicError, with_article
from ..spectra import get_spectrum
from .blender_colours import base_colour, corner_uvs, object_texture
from .blender_gloss import METAL_PROPERTY, principled_gloss
from .blender_world import world_lights
from .budget import SceneBudget
from .image_textures import corner_spectra
from .materials import METAL_SPECTRUM, material_problem
from .model import NON_DIFFUSE_KINDS, Camera, Light, Material, Mesh, Scene
from .textures import Texture, make_image_texture
from .validate import validate_scene

__all__ = ["load_blend", "SPECTRUM_PROPERTY", "METAL_PROPERTY", "base_colour", "principled_gloss"]

log = logging.getLogger(__name__)

#: Custom property naming a material's or a light's spectrum.
SPECTRUM_PROPERTY = "spectrum"
_MESH_LIKE = {"MESH", "CURVE", "SURFACE", "META", "FONT"}


def _require_bpy() -> Any:
    try:
        import bpy
    except ImportError as exc:
        raise MissingDependencyError(
            "reading .blend files needs bpy (Blender as a Python module): "
            "pip install 'spectrinsic[blender]'"
        ) from exc
    return bpy


def _matrix(obj: Any) -> np.ndarray:
    return np.array([list(row) for row in obj.matrix_world], dtype=np.float64)


def _prop(*owners: Any) -> str | None:
    for owner in owners:
        if owner is not None and SPECTRUM_PROPERTY in owner.keys():
            return str(owner[SPECTRUM_PROPERTY])
    return None


def _check_spectrum(
    source: str, field: str, name: str, kind: str, hint: str, data_dir: str | None
) -> None:
    try:
        spectrum = get_spectrum(name, data_dir=data_dir)
    except SpectrinsicError as exc:
        raise SceneError(f"{source}: {field}: {exc}; {hint}") from exc
    if spectrum.kind != kind:
        raise SceneError(
            f"{source}: {field}: {name!r} is {with_article(spectrum.kind)} spectrum; expected {with_article(kind)}"
        )


def _camera(source: str, bpy_scene: Any, resolution: tuple[int, int] | None) -> Camera:
    obj = bpy_scene.camera
    if obj is None:
        cams = [o for o in bpy_scene.objects if o.type == "CAMERA"]
        obj = cams[0] if cams else None
    if obj is None:
        raise SceneError(
            f"{source}: camera: the .blend has no camera; add one and make it the scene camera"
        )
    cam = obj.data
    if cam.type != "PERSP":
        raise SceneError(
            f"{source}: camera {obj.name!r}: type {cam.type!r} unsupported; expected a perspective camera"
        )
    if resolution is None:
        pct = bpy_scene.render.resolution_percentage / 100.0
        width = max(1, round(bpy_scene.render.resolution_x * pct))
        height = max(1, round(bpy_scene.render.resolution_y * pct))
    else:
        width, height = (int(v) for v in resolution)
    fit = cam.sensor_fit
    horizontal = fit == "HORIZONTAL" or (fit == "AUTO" and width >= height)
    sensor = cam.sensor_height if fit == "VERTICAL" else cam.sensor_width
    half = math.atan(sensor / (2.0 * cam.lens))
    if not horizontal:
        half = math.atan(math.tan(half) * width / height)
    if cam.shift_x or cam.shift_y:
        log.warning("camera %r: lens shift is ignored", obj.name)
    m = _matrix(obj)
    origin = m[:3, 3]
    forward = -m[:3, 2] / np.linalg.norm(m[:3, 2])
    up = m[:3, 1] / np.linalg.norm(m[:3, 1])
    return Camera(
        origin=tuple(map(float, origin)),  # type: ignore[arg-type]
        target=tuple(map(float, origin + forward)),  # type: ignore[arg-type]
        up=tuple(map(float, up)),  # type: ignore[arg-type]
        fov_deg=math.degrees(2 * half),
        width=width,
        height=height,
        name=obj.name,
    )


def _light(source: str, obj: Any, default: str, data_dir: str | None) -> Light:
    data = obj.data
    m = _matrix(obj)
    position = tuple(map(float, m[:3, 3]))
    dx, dy, dz = (float(v) for v in -m[:3, 2] / np.linalg.norm(m[:3, 2]))
    direction = (dx, dy, dz)
    spectrum = _prop(obj, data) or default
    _check_spectrum(
        source,
        f"light {obj.name!r}",
        spectrum,
        "illuminant",
        f"set the light's custom property {SPECTRUM_PROPERTY!r} to an illuminant name",
        data_dir,
    )
    energy = float(data.energy)
    kw: dict[str, Any] = {"spectrum": spectrum, "name": obj.name, "position": position}
    if data.type == "POINT":
        return Light(kind="point", power=energy / (4 * math.pi), **kw)
    if data.type == "SPOT":
        cutoff = min(math.degrees(data.spot_size) / 2, 90.0)
        return Light(
            kind="spot", power=energy / (4 * math.pi), direction=direction, cutoff_deg=cutoff, **kw
        )
    if data.type == "AREA":
        sx = float(data.size) * float(np.linalg.norm(m[:3, 0]))
        sy = float(data.size_y if data.shape in ("RECTANGLE", "ELLIPSE") else data.size) * float(
            np.linalg.norm(m[:3, 1])
        )
        if data.shape in ("DISK", "ELLIPSE"):
            # a rectangle of equal area keeps the emitted power
            sx, sy = sx * math.sqrt(math.pi) / 2, sy * math.sqrt(math.pi) / 2
            log.warning(
                "area light %r: %s shape approximated by a rectangle of equal area",
                obj.name,
                data.shape,
            )
        return Light(
            kind="area",
            power=energy / (math.pi * sx * sy),
            direction=direction,
            size=(sx, sy),
            **kw,
        )
    if data.type == "SUN":
        return Light(kind="directional", power=energy, direction=direction, **kw)
    raise SceneError(
        f"{source}: light {obj.name!r}: type {data.type!r} unsupported; expected POINT, SPOT, AREA or SUN"
    )


def _open_blend(bpy: Any, path: Path) -> None:
    """Open *path* in the running ``bpy`` session with the file's Python kept off."""
    source = str(path)
    if not path.is_file():
        raise SceneError(f"{source}: no such .blend file")
    # belt and braces: the preference and the operator flag both keep the file's Python off
    bpy.context.preferences.filepaths.use_scripts_auto_execute = False
    try:
        bpy.ops.wm.open_mainfile(filepath=str(path.resolve()), load_ui=False, use_scripts=False)
    except RuntimeError as exc:
        raise SceneError(
            f"{source}: cannot open as a .blend file ({' '.join(str(exc).split())})"
        ) from exc


class _MaterialTable:
    """Blender materials met so far, in order, each checked once to be a reflectance spectrum."""

    def __init__(
        self,
        source: str,
        mapping: Mapping[str, str],
        default_spectrum: str | None,
        data_dir: str | None,
        colours_from_asset: bool = True,
    ) -> None:
        self.source = source
        self.colours_from_asset = colours_from_asset
        self.mapping = dict(mapping)
        self.default_spectrum = default_spectrum
        self.data_dir = data_dir
        self.table: dict[str, Material] = {}

    def index(self, mat: Any, obj_name: str) -> int:
        """Index of the scene material for Blender material *mat* (None: the default one)."""
        if mat is None:
            if self.default_spectrum is None:
                raise SceneError(
                    f"{self.source}: object {obj_name!r}: faces without a material; assign one or pass default_spectrum="
                )
            name, spectrum = "default", self.default_spectrum
        else:
            name = mat.name
        try:  # glass without exact ground truth, colours in other primaries: name the file
            if mat is not None:
                spectrum = self.mapping.get(name) or _prop(mat) or self._colour(mat) or name
            gloss = principled_gloss(mat) if mat is not None else {}
        except SceneError as exc:
            raise SceneError(f"{self.source}: {exc}") from None
        if name not in self.table and gloss.get("kind") in NON_DIFFUSE_KINDS:
            material = Material(name=name, spectrum=METAL_SPECTRUM, **gloss)
            problem = material_problem(material)
            if problem:
                raise SceneError(f"{self.source}: material {name!r}: {problem}")
            self.table[name] = material
        if name not in self.table:
            _check_spectrum(
                self.source,
                f"material {name!r}",
                spectrum,
                "reflectance",
                f"name the material after a spectrum, set its custom property {SPECTRUM_PROPERTY!r}, "
                f"or pass materials={{{name!r}: ...}} (--material-map, --default-spectrum; "
                "--colours-from-asset reads a Base Color or image texture)",
                self.data_dir,
            )
            self.table[name] = Material(name=name, spectrum=spectrum, **gloss)
        return list(self.table).index(name)

    def _from_asset(self, mat: Any) -> bool:
        """Whether *mat* takes the file's colour: asked for, and neither mapped, nor given a
        spectrum property, nor named after a spectrum (module docstring)."""
        if not self.colours_from_asset or mat is None:
            return False
        if mat.name in self.mapping or _prop(mat) is not None:
            return False
        try:
            get_spectrum(mat.name, data_dir=self.data_dir)
        except SpectrinsicError:
            return True
        return False

    def _colour(self, mat: Any) -> str | None:
        """The base colour when the material takes the file's colour."""
        return base_colour(mat) if self._from_asset(mat) else None

    def texture(
        self, mats: Mapping[int, Any], uvs: Mapping[str, np.ndarray], obj: str
    ) -> Texture | None:
        """The image texture of object *obj* whose slots hold *mats*, or None
        (:func:`~spectrinsic.scenes.blender_colours.object_texture`)."""
        chosen = [m for m in mats.values() if self._from_asset(m)]
        where = f"{self.source}: object {obj!r}"
        hit = object_texture(chosen, len(mats), uvs, Path(self.source), where)
        if hit is None:
            return None
        mat, image, uv = hit
        if principled_gloss(mat):
            raise SceneError(f"{self.source}: material {mat.name!r} is textured and glossy")
        basis = []
        for spectrum in corner_spectra():
            self.table.setdefault(spectrum, Material(name=spectrum, spectrum=spectrum))
            basis.append(list(self.table).index(spectrum))
        return make_image_texture(mat.name, tuple(basis), image, uv)


_Triangles = tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, np.ndarray]]


def _triangles(obj: Any, depsgraph: Any, budget: SceneBudget) -> _Triangles | None:
    """Object-space vertices ``(V, 3)``, triangles ``(F, 3)``, material slots ``(F,)`` and
    corner UVs by map (:func:`~spectrinsic.scenes.blender_colours.corner_uvs`) of *obj* with
    its modifiers applied; None if it has no faces. Its counts are charged to *budget* before
    its arrays are copied out of Blender."""
    evaluated = obj.evaluated_get(depsgraph)
    me = evaluated.to_mesh()
    try:
        me.calc_loop_triangles()
        n_tri = len(me.loop_triangles)
        if n_tri == 0:
            return None
        budget.charge(f"object {obj.name!r}", faces=n_tri, vertices=len(me.vertices))
        co = np.empty(len(me.vertices) * 3, dtype=np.float64)
        me.vertices.foreach_get("co", co)
        tri = np.empty(n_tri * 3, dtype=np.int64)
        me.loop_triangles.foreach_get("vertices", tri)
        slot = np.empty(n_tri, dtype=np.int64)
        me.loop_triangles.foreach_get("material_index", slot)
        loops = np.empty(n_tri * 3, dtype=np.int64)
        me.loop_triangles.foreach_get("loops", loops)
        uvs = corner_uvs(me, loops.reshape(-1, 3))
    finally:
        evaluated.to_mesh_clear()
    return co.reshape(-1, 3), tri.reshape(-1, 3), slot, uvs


def _mesh(
    obj: Any, depsgraph: Any, materials: _MaterialTable, object_id: int, budget: SceneBudget
) -> Mesh | None:
    """*obj* as a world-space :class:`Mesh`, each face naming its scene material; None if empty."""
    triangles = _triangles(obj, depsgraph, budget)
    if triangles is None:
        return None
    co, faces, slot, uvs = triangles
    m = _matrix(obj)
    vertices = co @ m[:3, :3].T + m[:3, 3]
    if np.linalg.det(m[:3, :3]) < 0:  # a mirroring transform reverses the winding
        faces = faces[:, ::-1].copy()
        uvs = {k: uv[:, ::-1] for k, uv in uvs.items()}
    slots = [s.material for s in obj.material_slots] or [None]
    used = np.unique(slot)
    # Blender clamps indices past the last slot to it
    mats = {int(s): slots[min(int(s), len(slots) - 1)] for s in used}
    texture = materials.texture(mats, uvs, obj.name)
    lookup = np.zeros(int(used.max()) + 1, dtype=np.int64)
    for s in used if texture is None else ():
        lookup[s] = materials.index(mats[int(s)], obj.name)
    return Mesh(
        name=obj.name,
        vertices=vertices,
        faces=faces,
        face_materials=np.full(len(faces), texture.basis[0]) if texture else lookup[slot],
        object_id=object_id,
        texture=texture,
    )


def load_blend(
    path: str | os.PathLike[str],
    *,
    materials: Mapping[str, str] | None = None,
    light_spectrum: str = "cie:D65",
    default_spectrum: str | None = None,
    resolution: tuple[int, int] | None = None,
    data_dir: str | None = None,
    validate: bool = True,
    colours_from_asset: bool = True,
    approximate: bool = False,
) -> Scene:
    """Read a ``.blend`` file into a :class:`~spectrinsic.scenes.model.Scene`.

    Parameters
    ----------
    path
        The ``.blend`` file. Its Python scripts are never run.
    materials
        Blender material name -> reflectance spectrum name; overrides custom properties and
        material names.
    light_spectrum
        Illuminant of lights without a ``"spectrum"`` custom property.
    default_spectrum
        Reflectance of faces without a material; if None such faces are an error.
    resolution
        ``(width, height)`` in pixels; default: the file's render resolution and percentage.
    data_dir
        Spectral data directory for spectra that need one.
    validate
        Run :func:`~spectrinsic.scenes.validate.validate_scene` on the result.
    colours_from_asset
        Give materials without a spectrum their Principled Base Color as an ``rgb:``
        reflectance (module docstring, the default); False: they are an error.
    approximate
        Leave out, or approximate, a World without exact ground truth instead of refusing it,
        each phrase in ``scene.metadata["approximated"]``.

    Raises
    ------
    MissingDependencyError
        If ``bpy`` is not installed.
    SceneError
        One line naming the file and the object, material or field: no camera, an unknown
        spectrum, faces without a material, an unsupported light or camera type.
    """
    bpy = _require_bpy()
    path = Path(path)
    source = str(path)
    _open_blend(bpy, path)
    bpy_scene = bpy.context.scene
    camera = _camera(source, bpy_scene, resolution)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    table = _MaterialTable(source, materials or {}, default_spectrum, data_dir, colours_from_asset)
    meshes: list[Mesh] = []
    lights: list[Light] = []
    budget = SceneBudget(source)
    world = world_lights(bpy_scene.world, path, budget, approximate=approximate)  # before meshes
    for obj in sorted(bpy_scene.objects, key=lambda o: o.name):
        if obj.hide_render or not obj.visible_get():
            continue
        if obj.type == "LIGHT":
            lights.append(_light(source, obj, light_spectrum, data_dir))
        elif obj.type in _MESH_LIKE:
            mesh = _mesh(obj, depsgraph, table, object_id=len(meshes), budget=budget)
            if mesh is not None:
                meshes.append(mesh)
    metadata: dict[str, Any] = {"source": "blender", "file": path.name}
    metadata["blender"] = bpy.app.version_string
    if approximate:  # only then, so the records of other reads stay as they were
        metadata |= {"approximate": True, "approximated": list(world.approximated)}
    scene = Scene(
        name=path.stem,
        meshes=tuple(meshes),
        materials=tuple(table.table.values()),
        lights=(*lights, *world.lights),
        camera=camera,
        metadata=metadata,
    )
    if validate:
        validate_scene(scene, source=source, data_dir=data_dir)
    return scene
