"""Mitsuba XML scene files (``render scene.xml``) read into :class:`Scene` records.

The file goes through three steps, each in its own module:

1. :func:`~spectrinsic.scenes.mitsuba_files.prepare_xml` checks it before anything is loaded
   (a regular file of at most 4 MiB, no DOCTYPE, ``<include>`` inlined and every file it names
   confined to the scene's folder, with its SHA-256 for the provenance);
2. :func:`~spectrinsic.scenes.mitsuba_tree.parse_xml` parses it with Mitsuba's own parser
   (``$name`` defaults, every transform and point form, ``<ref>``, the 0.5/0.6 upgrade and the
   usual fixes, each said);
3. this module turns the parsed nodes into the scene: shapes
   (:mod:`~spectrinsic.scenes.mitsuba_shapes`, counted against the scene budget before any is
   built), BSDFs (:mod:`~spectrinsic.scenes.mitsuba_bsdfs`; their ``mask``, ``bumpmap`` and
   ``normalmap`` wrappers :mod:`~spectrinsic.scenes.mitsuba_maps`), emitters (``area`` on a
   ``rectangle`` or a ``sphere``, ``point``, ``spot``, ``directional``, ``constant`` as a sky,
   ``envmap`` as an environment map's three channel lights (:mod:`~spectrinsic.scenes.envmaps`);
   two skies are merged when their spectra agree, refused otherwise, and an environment map
   beside a sky is refused), the
   ``perspective`` sensor and its film (validated before any arithmetic), and the file's
   ``sample_count`` and ``max_depth`` as render hints.

What has no exact ground truth is refused in one line naming the element and the file; with
``approximate=True`` (``--approximate``) it is approximated instead, each approximation one
phrase in ``scene.metadata["approximated"]``. Fixes of old files are in ``["fixed"]`` and
settings that do not reach the render in ``["ignored"]``; the command line prints all three
(:func:`~spectrinsic.scenes.reading_notes.reading_notes`).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError, SpectrinsicError
from . import mitsuba_shapes as shapes
from .image_textures import ImageTexture, corner_spectra
from .mitsuba_bitmaps import diffuse_bitmap
from .mitsuba_bsdfs import DEFAULT_MATERIAL, material_of
from .mitsuba_environment import envmap_emitter
from .mitsuba_files import MAX_XML_BYTES, SceneFile, prepare_xml
from .mitsuba_maps import shape_maps
from .mitsuba_spectra import emission
from .mitsuba_sunsky import SKY_ROWS, sunsky_lights
from .mitsuba_tree import XmlNode, parse_xml
from .model import Camera, Light, Material, Mesh, Scene
from .surface_maps import MeshMaps
from .textures import make_image_texture
from .validate import validate_scene

__all__ = ["MAX_XML_BYTES", "ENVIRONMENT", "load_mitsuba_xml", "render_hints_line"]

#: Emitters that light the scene from infinity (one per scene in Mitsuba).
ENVIRONMENT = ("constant", "envmap", "sunsky", "sky", "sun")
#: Emitters without exact ground truth until the glass-and-environment issue lands.
_LATER = ("sky", "sun")
#: Mitsuba's default film size.
_FILM = (768, 576)


@dataclass
class _Reading:
    """What one read collects besides the scene: its folder, the approximation switch and the
    phrases said on stderr."""

    base: Path
    approximate: bool
    approximated: list[str] = field(default_factory=list)
    ignored: list[str] = field(default_factory=list)
    #: Environment maps read so far.
    maps: int = 0

    @property
    def say(self) -> Callable[[str], None] | None:
        return self.approximated.append if self.approximate else None

    def refuse_or_drop(self, node: XmlNode, where: str, what: str) -> None:
        if not self.approximate:
            raise SceneError(
                f"{where}: {node.label()} has no exact ground truth yet; refused "
                f"(--approximate: {what} left out)"
            )
        self.approximated.append(f"{where}: {node.label()} left out")  # the refusal says what


def _vec(value: Any) -> tuple[float, float, float]:
    return tuple(float(x) for x in np.asarray(value, float).reshape(3))  # type: ignore[return-value]


def _unit(v: np.ndarray, where: str = "a light") -> tuple[float, float, float]:
    """*v* scaled to unit length; a zero vector is refused (not divided by zero)."""
    length = float(np.linalg.norm(v))
    if not length > 0:
        raise SceneError(f"{where}: direction {_vec(v)} is a zero vector; expected a non-zero one")
    return _vec(v / length)


def _area_light(p: shapes.Placed, node: XmlNode, r: _Reading) -> Light | None:
    """The light of an ``area`` emitter on a rectangle (an area light) or a sphere (a sphere
    light)."""
    spectrum, power = emission(node.props.get("radiance"), f"{p.where} radiance", r.base)
    m = p.matrix @ np.asarray(p.node.props.get("to_world", np.eye(4)), float)
    if p.node.plugin == "sphere":
        centre = m[:3, :3] @ np.asarray(p.node.props.get("center", np.zeros(3)), float) + m[:3, 3]
        scales = np.linalg.norm(m[:3, :3], axis=0)
        if not np.allclose(scales, scales[0], rtol=1e-9):
            raise SceneError(f"{p.where}: an area sphere scaled unevenly is not a sphere")
        radius = shapes.sphere_radius(p) * float(scales[0])
        return Light("sphere", spectrum, power, position=_vec(centre), radius=radius, name=p.name)
    if p.node.plugin != "rectangle":
        r.refuse_or_drop(node, p.where, "the emitter (the shape stays, unlit)")
        return None
    u, v = m[:3, 0], m[:3, 1]
    # Mitsuba's normal: the inverse transpose of m applied to +z, i.e. u × v / det(m)
    normal = (
        -np.cross(u, v)
        if shapes.props_true(p.node, "flip_normals") ^ shapes.mirrors(m)
        else np.cross(u, v)
    )
    if not np.linalg.norm(normal) > 0:  # a rectangle scaled to a line or a point (or NaN)
        raise SceneError(
            f"{p.where}: an area emitter on a rectangle of zero area (its to_world scales it "
            "to a line or a point); expected a rectangle of positive area"
        )
    return Light(
        "area",
        spectrum,
        power,
        position=_vec(m[:3, 3]),
        direction=_unit(normal),
        size=(2 * float(np.linalg.norm(u)), 2 * float(np.linalg.norm(v))),
        name=p.name,
    )


def _emitter(node: XmlNode, where: str, r: _Reading) -> list[Light]:
    """The lights of a top-level emitter (none where an approximation leaves it out; three
    for an environment map)."""
    kind = node.plugin
    m = np.asarray(node.props.get("to_world", np.eye(4)), float)
    if kind in _LATER:
        r.refuse_or_drop(node, where, "this emitter")
        return []
    if kind == "envmap":
        r.maps += 1
        return envmap_emitter(node, where, r.base, r.maps)
    if kind == "sunsky":
        if not r.approximate:
            raise SceneError(
                f"{where}: {node.label()} has no exact ground truth yet; refused "
                "(--approximate: its sky baked into an RGB map, its sun a directional light)"
            )
        r.approximated.append(
            f"{where}: {node.label()} as Mitsuba's RGB sunsky: its sky baked into a "
            f"{SKY_ROWS} x {2 * SKY_ROWS} map, its sun a directional light"
        )
        return sunsky_lights(node, where, r.base)
    return [_single_emitter(node, kind, m, where, r.base)]


def _single_emitter(node: XmlNode, kind: str, m: np.ndarray, where: str, base: Path) -> Light:
    """The light of a top-level emitter other than an environment map."""
    if kind == "constant":
        spectrum, power = emission(node.props.get("radiance"), f"{where} radiance", base)
        return Light("sky", spectrum, power, name="sky")
    if kind == "directional":
        spectrum, power = emission(node.props.get("irradiance"), f"{where} irradiance", base)
        d = node.props.get("direction")
        direction = m[:3, 2] if d is None else m[:3, :3] @ np.asarray(d, float)
        return Light("directional", spectrum, power, direction=_unit(direction, where))
    spectrum, power = emission(node.props.get("intensity"), f"{where} intensity", base)
    if kind == "point":
        pos = node.props.get("position")
        return Light("point", spectrum, power, position=_vec(m[:3, 3] if pos is None else pos))
    if kind == "spot":
        cutoff = node.number("cutoff_angle", 20.0)
        if "beam_width" in node.props:
            raise SceneError(f"{where}: beam_width in {node.label()}; Mitsuba's default applies")
        direction = m[:3, 2]
        return Light(
            "spot", spectrum, power, position=_vec(m[:3, 3]), direction=_unit(direction, where),
            cutoff_deg=cutoff,
        )  # fmt: skip
    raise SceneError(f"{where}: unsupported element {node.label()}")


def _merged_sky(lights: list[Light], where: str) -> list[Light]:
    """*lights* with every sky merged into one (their radiances add; same spectrum only)."""
    skies = [light for light in lights if light.kind == "sky"]
    if len(skies) < 2:
        return lights
    if len({s.spectrum for s in skies}) > 1:
        raise SceneError(
            f"{where}: {len(skies)} environment emitters with different spectra; Mitsuba takes "
            "one (merge them into one <emitter type='constant'>)"
        )
    sky = Light("sky", skies[0].spectrum, sum(s.power for s in skies), name="sky")
    return [light for light in lights if light.kind != "sky"] + [sky]


def _film(sensor: XmlNode, where: str, r: _Reading) -> tuple[int, int]:
    films = [c for c in sensor.children if c.kind == "film"]
    if not films:
        return _FILM
    film = films[0]
    size = []
    for key, default in zip(("width", "height"), _FILM):
        value = film.props.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 1 << 16:
            raise SceneError(
                f"{where}: film {key} {value!r}; expected a whole number from 1 to 65536"
            )
        size.append(value)
    if any(c.kind == "rfilter" or c.kind == "reconstructionfilter" for c in film.children):
        r.ignored.append(f"{where}: the film's rfilter (spectrinsic's own filter applies)")
    return size[0], size[1]


def _fov_x(sensor: XmlNode, width: int, height: int, where: str) -> float:
    """Horizontal field of view in degrees from ``fov`` and ``fov_axis`` (or a 35 mm
    ``focal_length``, Mitsuba's rule: the film diagonal is 43.27 mm)."""
    props = sensor.props
    axis = str(props.get("fov_axis", "x"))
    if "focal_length" in props:
        mm = float(str(props["focal_length"]).removesuffix("mm"))
        fov, axis = math.degrees(2 * math.atan(math.hypot(36, 24) / (2 * mm))), "diagonal"
    else:
        fov = sensor.number("fov", 40.0)
    if not 0 < fov < 180:
        raise SceneError(f"{where}: fov {fov}; expected 0 < fov < 180 degrees")
    t = math.tan(math.radians(fov) / 2)
    ratio = {
        "x": 1.0,
        "y": width / height,
        "diagonal": width / math.hypot(width, height),
        "smaller": max(width / height, 1.0),
        "larger": min(width / height, 1.0),
    }
    if axis not in ratio:
        raise SceneError(f"{where}: fov_axis {axis!r}; expected x, y, diagonal, smaller or larger")
    return math.degrees(2 * math.atan(t * ratio[axis]))


def _camera(sensor: XmlNode, where: str, r: _Reading) -> Camera:
    if sensor.plugin != "perspective":
        raise SceneError(
            f"{where}: unsupported element {sensor.label()}; expected a perspective sensor"
        )
    width, height = _film(sensor, where, r)
    for key in ("near_clip", "far_clip", "principal_point_offset_x", "principal_point_offset_y"):
        if key in sensor.props:
            r.ignored.append(f"{where}: {key} (a pinhole camera without clipping applies)")
    m = np.asarray(sensor.props.get("to_world", np.eye(4)), float)
    # Mitsuba's camera looks along +z with +y up and x to the left: left-handed screen axes
    return Camera(
        origin=_vec(m[:3, 3]),
        target=_vec(m[:3, 3] + m[:3, 2]),
        up=_vec(m[:3, 1]),
        fov_deg=_fov_x(sensor, width, height, where),
        width=width,
        height=height,
    )


def _hints(root: XmlNode) -> dict[str, int]:
    """The file's ``sample_count`` and ``max_depth``, where it gives them."""
    out = {}
    for node in root.children:
        if node.kind == "integrator" and "max_depth" in node.props:
            out["max_depth"] = node.integer("max_depth", 0)
        for child in node.children if node.kind == "sensor" else ():
            if child.kind == "sampler" and "sample_count" in child.props:
                out["spp"] = child.integer("sample_count", 0)
    return out


def _shape_parts(
    p: shapes.Placed, r: _Reading
) -> tuple[Material | ImageTexture | None, Light | None]:
    """The material or bitmap image (``None``: the shape is left out) or the light of shape
    *p*."""
    bsdfs = [c for c in p.node.children if c.kind == "bsdf"]
    emitters = [c for c in p.node.children if c.kind == "emitter"]
    other = [c for c in p.node.children if c.kind not in ("bsdf", "emitter")]
    if other:
        raise SceneError(f"{p.where}: unsupported element {other[0].label()} in a shape")
    if len(bsdfs) > 1 or len(emitters) > 1:
        raise SceneError(f"{p.where}: expected at most one bsdf and one emitter")
    if emitters:
        if emitters[0].plugin != "area":
            raise SceneError(f"{p.where}: unsupported element {emitters[0].label()} in a shape")
        light = _area_light(p, emitters[0], r)
        if light is not None:
            return None, light
    if "face_normals" in p.node.props:
        r.ignored.append(f"{p.where}: face_normals (normals are smoothed below a 30° crease)")
    if not bsdfs:
        return DEFAULT_MATERIAL, None
    image = diffuse_bitmap(bsdfs[0], p.where, r.base)
    if image is not None:
        return image, None
    return material_of(bsdfs[0], p.where, r.base, r.say), None


def _textured_mesh(
    p: shapes.Placed, image: ImageTexture, r: _Reading, materials: dict[Material, int], i: int
) -> Mesh:
    """Shape *p* under bitmap *image*: its faces take the 8 RGB-cube corner materials."""
    v, f, uv = shapes.textured_triangles(p, r.base)
    basis = tuple(materials.setdefault(Material(s, s), len(materials)) for s in corner_spectra())
    texture = make_image_texture(p.name, basis, image, uv)
    mesh = Mesh(p.name, v, f, np.full(len(f), basis[0]), object_id=i, texture=texture)
    maps = _maps(p, r)
    return mesh if maps is None else replace(mesh, maps=replace(maps, uv=uv))


def _maps(p: shapes.Placed, r: _Reading) -> MeshMaps | None:
    """The mask and bump or normal map of shape *p*'s BSDF wrappers, without uv."""
    bsdfs = [c for c in p.node.children if c.kind == "bsdf"]
    return shape_maps(bsdfs[0], p.where, r.base) if bsdfs else None


def _mesh(p: shapes.Placed, r: _Reading, index: int, i: int) -> Mesh:
    """Shape *p* of one material *index* (by its texture coordinates where it has maps)."""
    maps = _maps(p, r)
    if maps is None:
        v, f = shapes.triangles(p, r.base)
        return Mesh(p.name, v, f, np.full(len(f), index), object_id=i)
    v, f, uv = shapes.textured_triangles(p, r.base)
    return Mesh(p.name, v, f, np.full(len(f), index), object_id=i, maps=replace(maps, uv=uv))


def _scene(root: XmlNode, name: str, r: _Reading) -> Scene:
    placed = shapes.occurrences(root)
    shapes.check_budget(placed, r.base)
    materials: dict[Material, int] = {}
    meshes: list[Mesh] = []
    lights: list[Light] = []
    cameras = []
    for p in placed:
        material, light = _shape_parts(p, r)
        if light is not None:
            lights.append(light)
        elif isinstance(material, ImageTexture):
            meshes.append(_textured_mesh(p, material, r, materials, len(meshes)))
        elif material is not None:
            index = materials.setdefault(material, len(materials))
            meshes.append(_mesh(p, r, index, len(meshes)))
    for i, node in enumerate(root.children):
        where = f"element {i} {node.label()}"
        if node.kind == "emitter":
            lights += _emitter(node, where, r)
        elif node.kind == "sensor":
            cameras.append(_camera(node, where, r))
        elif node.kind == "integrator" and node.plugin not in ("path", "volpath"):
            r.ignored.append(f"{where} (spectrinsic's own path tracer applies)")
        elif node.kind not in ("shape", "bsdf", "texture", "integrator"):
            raise SceneError(f"{where}: unsupported element {node.label()}")
    if not cameras:
        raise SceneError("no <sensor type='perspective'>; expected one")
    if len(cameras) > 1:
        r.ignored.append(f"{len(cameras) - 1} sensor(s) after the first")
    return Scene(
        name=name,
        meshes=tuple(meshes),
        materials=tuple(materials),
        lights=tuple(_merged_sky(lights, "environment emitters")),
        camera=cameras[0],
    )


def load_mitsuba_xml(
    path: str | os.PathLike[str], *, data_dir: str | None = None, approximate: bool = False
) -> Scene:
    """Read and validate a Mitsuba XML scene (module docstring).

    Parameters
    ----------
    approximate
        Approximate what has no exact ground truth instead of refusing it (``--approximate``).

    Raises
    ------
    SceneError
        ``"<file>: <element>: <problem>"`` in one line.
    """
    path = Path(path)
    try:
        prepared = prepare_xml(path)
        parsed = parse_xml(prepared.text, prepared.version)
        reading = _Reading(path.parent, approximate)
        scene = _scene(parsed.root, path.stem, reading)
    except SpectrinsicError as exc:
        raise SceneError(f"{path}: {exc}") from None
    except (ValueError, OSError) as exc:
        raise SceneError(f"{path}: {exc}") from None
    metadata: dict[str, Any] = {
        "source": f"{path.name} (Mitsuba XML {prepared.version})",
        "approximate": approximate,
        "files": [{"path": f.path, "role": f.role, "sha256": f.sha256} for f in prepared.files],
        "render_hints": _hints(parsed.root),
        "fixed": list(parsed.fixes),
        "approximated": reading.approximated,
        "ignored": reading.ignored,
    }
    spd = [f for f in prepared.files if f.role == "spd"]
    if spd:  # recorded beside the csv: files in each sample's meta.json (issue 47)
        metadata["spectrum_files"] = _spd_records(spd)
    scene = Scene(scene.name, scene.meshes, scene.materials, scene.lights, scene.camera, metadata)
    return validate_scene(scene, source=str(path), data_dir=data_dir)


def _spd_records(files: list[SceneFile]) -> list[dict[str, str]]:
    """``meta.json["spectrum_files"]`` records of the ``.spd`` files read (their values are
    written out in the scene's spectrum names), by their path relative to the XML file's
    folder (:class:`SceneFile`; no path of the machine that built the sample is recorded)."""
    out = []
    for f in sorted(files, key=lambda f: f.path):
        out.append({"spectrum": f"spd:{f.path}", "file": f.path, "sha256": f.sha256})
    return out


def render_hints_line(
    scene: Scene, spp: int | None, max_depth: int | None, given: str = "the command line"
) -> str | None:
    """The line saying which spp and path depth apply to a Mitsuba XML scene: the file's
    (``sample_count``, ``max_depth``) unless *given* (the command line, a dataset's settings)
    sets *spp* / *max_depth*; ``None`` when the file gives neither."""
    hints = scene.metadata.get("render_hints") or {}
    if not hints:
        return None
    parts = []
    for key, label, value in (("spp", "spp", spp), ("max_depth", "max depth", max_depth)):
        if key in hints:
            parts.append(
                f"{label} {hints[key]} from the file"
                if value is None
                else f"{label} {value} from {given} (the file says {hints[key]})"
            )
    return f"{scene.name}: " + ", ".join(parts)
