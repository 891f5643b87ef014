"""Mitsuba 3 XML scene files (``render scene.xml``) read into :class:`Scene` records.

A safe subset, read with :mod:`xml.etree.ElementTree` (never Mitsuba's loader, which would run
plugins and read any path): files of at most :data:`MAX_XML_BYTES`, no DOCTYPE or entity
declarations, no ``<include>``, mesh files only inside the scene's folder
(:func:`~spectrinsic.scenes.spectrum_refs.confined_csv`'s rules). ``$name`` parameters take
their ``<default>`` values. Translated:

- shapes ``obj``, ``ply`` (``filename``), ``rectangle``, ``cube``, ``disk``, ``sphere``
  (``center``, ``radius``), each with a ``to_world`` transform; built-in shapes become triangles
  (:mod:`~spectrinsic.scenes.mitsuba_parts`);
- BSDFs ``diffuse`` (``reflectance`` as ``rgb``: linear sRGB through Mallett & Yuksel 2019;
  ``spectrum``: ``"WL:V, ..."``, one number or a ``filename`` of a ``.spd`` file in the
  scene's folder; ``float``), ``plastic`` and ``roughplastic``
  (``diffuse_reflectance`` likewise, ``int_ior``/``ext_ior`` as numbers, ``alpha``: taken as the
  GGX α whatever the ``distribution``), ``conductor`` and ``roughconductor`` (``material`` one
  of Mitsuba's measured metals), bare or in a ``twosided``, at the top level with an ``id``
  (``<ref id=.../>``) or inside a shape;
- emitters ``area`` on a ``rectangle`` (an area light of the rectangle's centre, normal and
  size), ``point``, ``spot`` (``cutoff_angle``; Mitsuba's default ``beam_width``), ``directional``
  and ``constant`` (a ``sky`` light), with ``rgb`` (grey: D65)
  or ``spectrum`` emission (:func:`~spectrinsic.scenes.mitsuba_parts.emission`);
- the ``perspective`` sensor (``fov``, ``fov_axis`` x or y, ``to_world``) and its film's
  ``width`` and ``height``.

``integrator``, ``sampler`` and ``rfilter`` elements are ignored (the render's settings apply).
Anything else is refused in one line naming the element and the file.
"""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError, SpectrinsicError
from ..spectra.io import read_spd
from ..spectra.user_spectra import sha256
from . import mitsuba_parts as parts
from .materials import METAL_SPECTRUM
from .meshes import check_mesh_size
from .model import Camera, Light, Material, Mesh, Scene
from .validate import validate_scene

__all__ = ["MAX_XML_BYTES", "load_mitsuba_xml"]

MAX_XML_BYTES = 4 * 1024 * 1024
_IGNORED = ("integrator", "sampler", "rfilter")
_SHAPES = ("obj", "ply", "rectangle", "cube", "disk", "sphere")


def _named(el: ET.Element, name: str) -> ET.Element | None:
    return next((c for c in el if c.get("name") == name), None)


def _float(el: ET.Element, name: str, default: float, what: str) -> float:
    child = _named(el, name)
    return default if child is None else float(parts.numbers(child.get("value"), 1, what)[0])


def _label(el: ET.Element) -> str:
    attrs = " ".join(f"{k}={v!r}" for k, v in el.attrib.items() if k in ("type", "id", "name"))
    return f"<{el.tag}{' ' + attrs if attrs else ''}>"


def _parse(path: Path) -> ET.Element:
    """The root ``<scene>`` with ``$name`` defaults substituted."""
    size = path.stat().st_size
    if size > MAX_XML_BYTES:
        raise SceneError(f"{size} bytes; expected a scene file of at most {MAX_XML_BYTES} bytes")
    text = path.read_text(encoding="utf-8", errors="replace")
    if re.search(r"<!(DOCTYPE|ENTITY)", text):
        raise SceneError("DOCTYPE and ENTITY declarations are not allowed")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise SceneError(f"malformed XML ({exc})") from None
    if root.tag != "scene":
        raise SceneError(f"root element <{root.tag}>; expected <scene>")
    defaults = {d.get("name", ""): d.get("value", "") for d in root.iter("default")}
    for el in root.iter():
        for key, value in el.attrib.items():
            if "$" in value:
                el.set(
                    key, re.sub(r"\$(\w+)", lambda m: defaults.get(m.group(1), m.group(0)), value)
                )
    return root


_BSDF_PARAMS = {
    "diffuse": ("reflectance",),
    "plastic": ("diffuse_reflectance", "int_ior", "ext_ior"),
    "roughplastic": ("diffuse_reflectance", "int_ior", "ext_ior", "alpha", "distribution"),
    "conductor": ("material",),
    "roughconductor": ("material", "alpha", "distribution"),
}


def _read_spectrum_files(root: ET.Element, base: Path) -> list[dict[str, str]]:
    """Every ``<spectrum filename=...>`` (a Mitsuba ``.spd`` inside the scene's folder) made a
    ``value`` of its samples, so the rest of the reader sees written-out spectra; one record
    per file read (its path and SHA-256), for ``meta.json["spectrum_files"]``."""
    records: dict[str, dict[str, str]] = {}
    for el in root.iter("spectrum"):
        if "filename" not in el.attrib:
            continue
        rel = el.attrib.pop("filename")
        path = (base.resolve() / rel).resolve()
        if Path(rel).is_absolute() or not path.is_relative_to(base.resolve()):
            raise SceneError(
                f"spectrum filename {rel!r}; expected a path inside the scene's folder"
            )
        wl, values = read_spd(path)
        el.set("value", ", ".join(f"{w!r}:{v!r}" for w, v in zip(wl.tolist(), values.tolist())))
        records[str(path)] = {"spectrum": f"spd:{path}", "file": str(path), "sha256": sha256(path)}
    return [records[k] for k in sorted(records)]


def _bsdf(el: ET.Element, where: str) -> Material:
    """The material of a ``diffuse``, ``(rough)plastic`` or ``(rough)conductor`` BSDF, bare or
    inside a ``twosided``; named after its spectrum (diffuse) or its ``id``."""
    name = el.get("id", "")
    if el.get("type") == "twosided":
        inner = [c for c in el if c.tag == "bsdf"]
        if len(inner) != 1:
            raise SceneError(f"{where}: {_label(el)} needs exactly one inner <bsdf>")
        el = inner[0]
    kind = el.get("type", "")
    if kind not in _BSDF_PARAMS:
        raise SceneError(
            f"{where}: unsupported element {_label(el)}; expected a bsdf of type "
            + ", ".join(_BSDF_PARAMS)
        )
    for child in el:
        if child.get("name") not in _BSDF_PARAMS[kind]:
            raise SceneError(f"{where}: unsupported element {_label(child)} in {_label(el)}")
    alpha = _float(el, "alpha", 0.1, f"{where} alpha") if kind.startswith("rough") else 0.0
    if kind == "diffuse":
        spectrum = parts.reflectance_name(_named(el, "reflectance"), f"{where} reflectance")
        return Material(spectrum, spectrum)
    if kind.endswith("conductor"):
        metal = _named(el, "material")
        if metal is None:
            raise SceneError(f"{where}: {_label(el)} needs a 'material' (Au, Cu, Al, ...)")
        return Material(
            name or f"{kind} {metal.get('value')}",
            METAL_SPECTRUM,
            kind="conductor",
            roughness=alpha,
            metal=metal.get("value", ""),
        )
    base = parts.reflectance_name(_named(el, "diffuse_reflectance"), f"{where} reflectance")
    ior = _float(el, "int_ior", 1.49, f"{where} int_ior") / _float(el, "ext_ior", 1.0, where)
    return Material(name or f"{kind} {base}", base, kind="plastic", roughness=alpha, ior=ior)


def _mesh_file(el: ET.Element, base: Path, where: str) -> tuple[np.ndarray, np.ndarray]:
    import trimesh

    child = _named(el, "filename")
    rel = "" if child is None else child.get("value", "")
    root = base.resolve()
    path = (root / rel).resolve()
    if not rel or Path(rel).is_absolute() or not path.is_relative_to(root):
        raise SceneError(f"{where}: filename {rel!r}; expected a path inside the scene's folder")
    if not path.is_file() or path.suffix.lower() != f".{el.get('type')}":
        raise SceneError(f"{where}: mesh file {rel!r} not found as a .{el.get('type')} file")
    check_mesh_size(path)
    try:
        mesh: Any = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types for corrupt files
        raise SceneError(f"{where}: cannot read {rel!r} ({type(exc).__name__})") from None
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)


def _geometry(el: ET.Element, base: Path, where: str) -> tuple[np.ndarray, np.ndarray]:
    kind = el.get("type", "")
    if kind in ("obj", "ply"):
        v, f = _mesh_file(el, base, where)
    elif kind == "sphere":
        c = _named(el, "center")
        centre = np.zeros(3) if c is None else parts.numbers(c.get("value"), 3, where)
        if c is not None and "value" not in c.attrib:
            centre = np.array([float(c.get(k, 0)) for k in "xyz"])
        v, f = parts.sphere(centre, _float(el, "radius", 1.0, f"{where} radius"))
    else:
        v, f = getattr(parts, kind)()
    flip = _named(el, "flip_normals")
    if flip is not None and flip.get("value", "false").lower() == "true":
        f = f[:, ::-1]
    return parts.apply(parts.transform(_named(el, "to_world"), where), v), f


def _area_light(el: ET.Element, emitter: ET.Element, where: str) -> Light:
    if el.get("type") != "rectangle":
        raise SceneError(f"{where}: an area emitter on {_label(el)}; only on a rectangle")
    m = parts.transform(_named(el, "to_world"), where)
    u, v = m[:3, 0], m[:3, 1]
    normal = np.cross(u, v)
    flip = _named(el, "flip_normals")
    if flip is not None and flip.get("value", "false").lower() == "true":
        normal = -normal
    spectrum, power = parts.emission(_named(emitter, "radiance"), f"{where} radiance")
    return Light(
        "area",
        spectrum,
        power,
        position=tuple(float(x) for x in m[:3, 3]),  # type: ignore[arg-type]
        direction=tuple(float(x) for x in normal / np.linalg.norm(normal)),  # type: ignore[arg-type]
        size=(2 * float(np.linalg.norm(u)), 2 * float(np.linalg.norm(v))),
        name=el.get("id", "light"),
    )


def _emitter(el: ET.Element, where: str) -> Light:
    kind = el.get("type")
    if kind == "point":
        spectrum, power = parts.emission(_named(el, "intensity"), f"{where} intensity")
        p = _named(el, "position")
        pos = (
            parts.numbers(p.get("value"), 3, where)
            if p is not None and "value" in p.attrib
            else np.array([float(p.get(k, 0)) for k in "xyz"])
            if p is not None
            else parts.transform(_named(el, "to_world"), where)[:3, 3]
        )
        return Light("point", spectrum, power, position=tuple(float(x) for x in pos))  # type: ignore[arg-type]
    if kind == "directional":
        spectrum, power = parts.emission(_named(el, "irradiance"), f"{where} irradiance")
        d = _named(el, "direction")
        direction = parts.numbers(None if d is None else d.get("value"), 3, f"{where} direction")
        return Light("directional", spectrum, power, direction=tuple(float(x) for x in direction))  # type: ignore[arg-type]
    if kind == "spot":
        spectrum, power = parts.emission(_named(el, "intensity"), f"{where} intensity")
        m = parts.transform(_named(el, "to_world"), where)
        return Light(
            "spot",
            spectrum,
            power,
            position=tuple(float(x) for x in m[:3, 3]),  # type: ignore[arg-type]
            direction=tuple(float(x) for x in m[:3, 2] / np.linalg.norm(m[:3, 2])),  # type: ignore[arg-type]
            cutoff_deg=_float(el, "cutoff_angle", 20.0, f"{where} cutoff_angle"),
        )
    if kind == "constant":
        spectrum, power = parts.emission(_named(el, "radiance"), f"{where} radiance")
        return Light("sky", spectrum, power)
    raise SceneError(f"{where}: unsupported element {_label(el)}")


def _camera(el: ET.Element, where: str) -> Camera:
    if el.get("type") != "perspective":
        raise SceneError(
            f"{where}: unsupported element {_label(el)}; expected a perspective sensor"
        )
    film = next((c for c in el if c.tag == "film"), None)
    width = int(_float(film, "width", 768, where)) if film is not None else 768
    height = int(_float(film, "height", 576, where)) if film is not None else 576
    fov = _float(el, "fov", 40.0, f"{where} fov")
    axis = _named(el, "fov_axis")
    if axis is not None and axis.get("value") == "y":
        fov = math.degrees(2 * math.atan(math.tan(math.radians(fov) / 2) * width / height))
    elif axis is not None and axis.get("value") != "x":
        raise SceneError(f"{where}: fov_axis {axis.get('value')!r}; expected x or y")
    m = parts.transform(_named(el, "to_world"), where)
    origin = m[:3, 3]
    return Camera(
        origin=tuple(float(x) for x in origin),  # type: ignore[arg-type]
        target=tuple(float(x) for x in origin + m[:3, 2]),  # type: ignore[arg-type]
        up=tuple(float(x) for x in m[:3, 1]),  # type: ignore[arg-type]
        fov_deg=fov,
        width=width,
        height=height,
    )


def _shape(
    el: ET.Element, base: Path, bsdfs: dict[str, Material], where: str
) -> tuple[Material | None, tuple[np.ndarray, np.ndarray] | None, Light | None]:
    """``(material, geometry, None)`` of a surface or ``(None, None, light)`` of an area light."""
    if el.get("type") not in _SHAPES:
        raise SceneError(f"{where}: unsupported element {_label(el)}")
    emitters = [c for c in el if c.tag == "emitter"]
    if emitters:
        if emitters[0].get("type") != "area":
            raise SceneError(f"{where}: unsupported element {_label(emitters[0])} in a shape")
        return None, None, _area_light(el, emitters[0], where)
    material = Material("flat:0.5", "flat:0.5")  # Mitsuba's default BSDF
    for child in el:
        if child.tag == "ref":
            if child.get("id") not in bsdfs:
                raise SceneError(f"{where}: <ref id={child.get('id')!r}> names no bsdf")
            material = bsdfs[child.get("id", "")]
        elif child.tag == "bsdf":
            material = _bsdf(child, where)
        elif child.tag not in ("string", "float", "point", "transform", "boolean"):
            raise SceneError(f"{where}: unsupported element {_label(child)}")
    return material, _geometry(el, base, where), None


def _scene(root: ET.Element, base: Path, name: str) -> Scene:
    bsdfs: dict[str, Material] = {}
    materials: dict[Material, int] = {}
    meshes: list[Mesh] = []
    lights: list[Light] = []
    camera = None
    for i, el in enumerate(root):
        where = f"element {i}" + (f" (id {el.get('id')!r})" if el.get("id") else "")
        if el.tag in _IGNORED or el.tag == "default":
            continue
        if el.tag == "bsdf" and el.get("id"):
            bsdfs[el.get("id", "")] = _bsdf(el, where)
        elif el.tag == "sensor":
            camera = _camera(el, where)
        elif el.tag == "emitter":
            lights.append(_emitter(el, where))
        elif el.tag == "shape":
            material, geometry, light = _shape(el, base, bsdfs, where)
            if light is not None:
                lights.append(light)
            elif material is not None and geometry is not None:
                index = materials.setdefault(material, len(materials))
                v, f = geometry
                meshes.append(
                    Mesh(
                        el.get("id", f"shape{i}"),
                        v,
                        f,
                        np.full(len(f), index),
                        object_id=len(meshes),
                    )
                )
        else:
            raise SceneError(f"unsupported element {_label(el)}")
    if camera is None:
        raise SceneError("no <sensor type='perspective'>; expected one")
    return Scene(
        name=name,
        meshes=tuple(meshes),
        materials=tuple(materials),
        lights=tuple(lights),
        camera=camera,
        metadata={"source": f"{name}.xml (Mitsuba 3 XML)"},
    )


def load_mitsuba_xml(path: str | os.PathLike[str], *, data_dir: str | None = None) -> Scene:
    """Read and validate a Mitsuba 3 XML scene (module docstring).

    Raises
    ------
    SceneError
        ``"<file>: <element>: <problem>"`` in one line.
    """
    path = Path(path)
    try:
        root = _parse(path)
        if any(el.tag == "include" for el in root.iter()):
            raise SceneError("unsupported element <include>")
        spd_files = _read_spectrum_files(root, path.parent)
        scene = _scene(root, path.parent, path.stem)
        if spd_files:  # recorded beside the csv: files in each sample's meta.json
            scene.metadata["spectrum_files"] = spd_files
    except SpectrinsicError as exc:
        raise SceneError(f"{path}: {exc}") from None
    except (ValueError, OSError) as exc:
        raise SceneError(f"{path}: {exc}") from None
    return validate_scene(scene, source=str(path), data_dir=data_dir)
