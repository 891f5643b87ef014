"""The scene model: a scene is plain data.

Geometry is arrays; materials, lights and the camera are frozen records that *name* spectra
(``"munsell:5R 4/14"``, ``"planck:2800K"``) from :mod:`spectrinsic.spectra` rather than hold
colours, so any layer of ground truth can be recomputed from the spectra. A scene can be
compared, hashed (:func:`scene_hash`) and written as JSON (:func:`scene_to_dict`) next to every
rendered sample. Only :mod:`spectrinsic.render` translates a scene into a Mitsuba dict.

Units: lengths in scene units (metres by convention), angles in degrees, wavelengths in nm.
Materials are Lambertian by default (as in the thesis dataset); a material may instead be a
coated diffuse (``plastic``) or a metal (``conductor``), smooth or rough (:class:`Material`).
"""

# long module: one concept, the scene record (materials, meshes, lights, camera) and
# its one plain-data form (scene_to_dict / scene_from_dict / scene_hash), which must change together

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, is_dataclass
from typing import Any, Literal

import numpy as np

from ..errors import SceneError, did_you_mean
from .semantic import classify
from .surface_maps import MeshMaps, maps_from_record
from .textures import Texture, texture_from_record

__all__ = [
    "Material",
    "MaterialKind",
    "MATERIAL_KINDS",
    "NON_DIFFUSE_KINDS",
    "TRANSMISSIVE_KINDS",
    "GLOSS_FIELDS",
    "Mesh",
    "Light",
    "Camera",
    "Scene",
    "LightKind",
    "LIGHT_FIELDS",
    "LIGHT_KINDS",
    "DRAWN_LIGHT_KINDS",
    "LIGHT_PLACEMENT",
    "LIGHT_DEFAULTED",
    "IDENTITY_ROTATION",
    "ENVMAP_CHANNELS",
    "make_light",
    "unknown_light_kind",
    "light_power",
    "record_fields",
    "scene_to_dict",
    "scene_from_dict",
    "scene_hash",
    "scene_record_hash",
]

LightKind = Literal["point", "spot", "area", "directional", "sky", "sphere", "envmap"]
#: The one table of light kinds: the placement fields each kind uses (the others are ignored,
#: and records such as meta.json leave them out).
LIGHT_FIELDS: dict[str, tuple[str, ...]] = {
    "point": ("position",),
    "spot": ("position", "direction", "cutoff_deg"),
    "area": ("position", "direction", "size"),
    "directional": ("direction",),
    "sky": (),
    "sphere": ("position", "radius"),
    "envmap": (),  # placed at infinity; its map's file record: Light.file ... rotation
}
#: The light kinds, in the table's order (``typing.get_args(LightKind)`` is the same).
LIGHT_KINDS: tuple[LightKind, ...] = tuple(LIGHT_FIELDS)  # type: ignore[arg-type]
#: The kinds the scene generators draw (a sky comes from scene files and daylight rooms, a
#: sphere and an environment map from Mitsuba XML files).
DRAWN_LIGHT_KINDS: tuple[LightKind, ...] = tuple(
    k for k in LIGHT_KINDS if k not in ("sky", "sphere", "envmap")
)
#: Every placement field some kind uses (the union of :data:`LIGHT_FIELDS`).
LIGHT_PLACEMENT: tuple[str, ...] = tuple(
    dict.fromkeys(f for fs in LIGHT_FIELDS.values() for f in fs)
)
#: Placement fields with a default that a scene file may leave out (a spot's cone half-angle,
#: :attr:`Light.cutoff_deg`).
LIGHT_DEFAULTED: tuple[str, ...] = ("cutoff_deg",)
#: The identity rotation of an environment map (:attr:`Light.rotation`).
IDENTITY_ROTATION = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
#: Suffixes of the three channel lights of one environment map (:attr:`Light.channel`).
ENVMAP_CHANNELS = (".r", ".g", ".b")


MaterialKind = Literal["diffuse", "plastic", "conductor", "dielectric", "thindielectric"]
#: Material kinds: Lambertian; a diffuse base under a dielectric coat (Mitsuba ``plastic`` /
#: ``roughplastic``); a metal (``conductor`` / ``roughconductor``); clear glass, a solid
#: (``dielectric`` / ``roughdielectric``) or a thin pane (``thindielectric``).
MATERIAL_KINDS: tuple[MaterialKind, ...] = (
    "diffuse",
    "plastic",
    "conductor",
    "dielectric",
    "thindielectric",
)
#: Kinds without a diffuse lobe (reflectance 0; shading the white-Lambertian ``W = E/π``).
NON_DIFFUSE_KINDS: tuple[MaterialKind, ...] = ("conductor", "dielectric", "thindielectric")
#: Kinds that transmit light (glass, clear or tinted).
TRANSMISSIVE_KINDS: tuple[MaterialKind, ...] = ("dielectric", "thindielectric")
#: The optional fields of :class:`Material`; at their defaults they are left out of
#: :func:`scene_to_dict`, so a matte scene's record and hash are those of before they existed.
GLOSS_FIELDS = ("kind", "roughness", "ior", "metal", "transmittance", "specular_reflectance")
#: A glass's tint fields (spectrum names, ``""`` untinted) and the Mitsuba parameter each is:
#: the transmitted and the reflected lobe's factor.
GLASS_TINTS = {
    "transmittance": "specular_transmittance",
    "specular_reflectance": "specular_reflectance",
}
_OPTIONAL = {"omit_default": True}


@dataclass(frozen=True)
class Material:
    """A material: Lambertian (default), coated diffuse, metal or glass (clear or tinted).

    Attributes
    ----------
    name
        Human-readable name (``"wall"``, ``"stripe 2"``).
    spectrum
        Registry name of the diffuse reflectance spectrum, e.g. ``"munsell:5R 4/14"`` (the base
        under the coat of a ``plastic``; ``"flat:0"`` for a ``conductor`` or glass, which have
        no diffuse lobe).
    kind
        One of :data:`MATERIAL_KINDS`.
    roughness
        GGX α of the coat, metal or glass surface (dimensionless, 0 = smooth, i.e. a delta
        lobe); ignored for ``diffuse``; 0 for ``thindielectric``.
    ior
        Index of refraction of a ``plastic``'s coat or of glass, relative to the outside
        (Mitsuba's ``int_ior / ext_ior``); constant over wavelength (no dispersion).
    metal
        Name of a conductor whose measured η/k Mitsuba ships (``Au``, ``Cu``, ``Al``, ``Ag``...),
        or ``none`` for a perfect mirror (F = 1, Mitsuba's ``material: none``), for
        ``conductor``.
    transmittance
        Registry name of a glass's transmittance spectrum T(λ), a fraction in [0, 1] (a
        reflectance-kind name: ``rgb:``, ``munsell:``, ``csv:``, ``inline:``...), or ``""``
        for clear glass (T = 1). It multiplies every transmission through the surface (each
        refraction of a ``dielectric``, the straight pass of a ``thindielectric``), not its
        reflections, as Mitsuba's ``specular_transmittance``; only for glass kinds.
    specular_reflectance
        Registry name of a glass's or conductor's reflection tint R_t(λ) in [0, 1] (as
        *transmittance*), or ``""`` (1): it multiplies every reflection off the surface (the
        Fresnel-weighted reflected lobe), not its transmissions, as Mitsuba's
        ``specular_reflectance``; only for glass and conductor kinds (a Blender Glass BSDF's
        Color is both of a glass's tints; a tinted ``metal: none`` is a coloured mirror).
    """

    name: str
    spectrum: str
    kind: MaterialKind = field(default="diffuse", metadata=_OPTIONAL)
    roughness: float = field(default=0.0, metadata=_OPTIONAL)
    ior: float = field(default=1.5, metadata=_OPTIONAL)
    metal: str = field(default="", metadata=_OPTIONAL)
    transmittance: str = field(default="", metadata=_OPTIONAL)
    specular_reflectance: str = field(default="", metadata=_OPTIONAL)

    @property
    def glossy(self) -> bool:
        """Whether the material has a non-diffuse lobe."""
        return self.kind != "diffuse"

    @property
    def non_diffuse(self) -> bool:
        """Whether the material has no diffuse lobe (metal, mirror, glass)."""
        return self.kind in NON_DIFFUSE_KINDS

    @property
    def transmissive(self) -> bool:
        """Whether the material is glass (transmits light)."""
        return self.kind in TRANSMISSIVE_KINDS

    @property
    def tinted(self) -> bool:
        """Whether the material is glass with a transmittance or reflection tint (not clear)."""
        return self.transmissive and bool(self.transmittance or self.specular_reflectance)

    def tint(self, key: str) -> str:
        """The spectrum name of tint *key* (of :data:`GLASS_TINTS`), ``"flat:1"`` where
        untinted (:func:`material_problem` allows tints on glass and conductors only)."""
        return str(getattr(self, key)) or "flat:1"


def _named_class(mesh: Mesh) -> bool:
    """Whether *mesh*'s class is the one its name gives (left out of its record then)."""
    return mesh.semantic == classify([mesh.name])


@dataclass(frozen=True, eq=False)
class Mesh:
    """A triangle mesh in world space with one material index per face.

    Attributes
    ----------
    name
        Object name, unique in its scene.
    vertices
        ``(V, 3)`` float64 world-space positions.
    faces
        ``(F, 3)`` int64 vertex indices, counter-clockwise seen from outside.
    face_materials
        ``(F,)`` int64 indices into :attr:`Scene.materials`; lets one object carry several
        exact spectra (painted stripes, patches).
    object_id
        Non-negative id written to the object-id ground-truth map.
    texture
        A spectral :class:`~spectrinsic.scenes.textures.Texture` over every face (whose
        ``face_materials`` are then all ``texture.basis[0]``), or ``None``: each face one exact
        spectrum. Left out of :func:`scene_to_dict` when ``None``.
    semantic
        Its class in :data:`~spectrinsic.scenes.semantic.SEMANTIC_CLASSES`; left empty, the
        class its name maps to by the default map
        (:func:`~spectrinsic.scenes.semantic.classify`). Left out of :func:`scene_to_dict`
        when it is that class, so the records and hashes of scenes from before classes existed
        are unchanged. ``dataclasses.replace(mesh, name=...)`` keeps the class; add
        ``semantic=""`` to take the new name's.
    maps
        Its opacity mask and bump or normal map (:class:`~spectrinsic.scenes.surface_maps.MeshMaps`),
        or ``None``: opaque, unperturbed. Left out of :func:`scene_to_dict` when ``None``.
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    face_materials: np.ndarray
    object_id: int
    texture: Texture | None = field(default=None, metadata=_OPTIONAL)
    semantic: str = field(default="", metadata={"omit_when": _named_class})
    maps: MeshMaps | None = field(default=None, metadata=_OPTIONAL)

    def __post_init__(self) -> None:
        if not self.semantic:  # the class of its name (frozen: set once, here)
            object.__setattr__(self, "semantic", classify([self.name]))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Mesh):
            return NotImplemented
        return (
            self.name == other.name
            and self.object_id == other.object_id
            and np.array_equal(self.vertices, other.vertices)
            and np.array_equal(self.faces, other.faces)
            and np.array_equal(self.face_materials, other.face_materials)
            and self.texture == other.texture
            and self.semantic == other.semantic
            and self.maps == other.maps
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class Light:
    """A light source with the relative spectral power distribution called *spectrum*.

    Attributes
    ----------
    kind
        One of :data:`LIGHT_KINDS`: ``"point"``, ``"spot"``, ``"area"`` (a rectangle),
        ``"directional"``, ``"sky"`` (a uniform sky dome at infinity, Mitsuba ``constant``) or
        ``"sphere"`` (a sphere of uniform radiance, emitting on its outside) or ``"envmap"``
        (one RGB channel of an equirectangular radiance map at infinity, Mitsuba ``envmap``:
        an environment map is three such lights, channels 0, 1, 2 of one file, of spectra
        ``rgblight:1,0,0`` ... and powers ``scale · rgb_light_power``, named
        ``<map>.r/.g/.b``; ``docs/envmap_design.md``); :data:`LIGHT_FIELDS` lists the
        placement fields each uses.
    spectrum
        Registry name of an illuminant, e.g. ``"planck:2800K"``. The registry normalises every
        illuminant to unit luminance-weighted mean, so *power* alone sets brightness.
    power
        Scale on the normalised SPD: radiant intensity for point and spot lights, radiance for
        area and sphere lights and the sky (an unoccluded surface then receives irradiance π × power),
        irradiance for directional lights (relative units). Must be > 0.
    position
        World position (point, spot, area centre); unused for directional lights.
    direction
        Direction the light travels (spot, area normal, directional); unused for point lights.
    size
        ``(width, height)`` of an area light in scene units.
    cutoff_deg
        Spot cone half-angle in degrees.
    radius
        Radius of a sphere light in scene units (left out of records at its default).
    file
        An environment map's file (OpenEXR or Radiance HDR, linear RGB radiance), an absolute
        path checked when the scene was read; left out of records when empty.
    sha256
        SHA-256 of :attr:`file` when read, so the scene's hash changes with the map.
    channel
        Which RGB channel of :attr:`file` this light is (0, 1, 2).
    rotation
        The map's ``to_world`` rotation, 3 x 3 row-major (Mitsuba's envmap frame: +y up).
    """

    kind: LightKind
    spectrum: str
    power: float
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    size: tuple[float, float] = (1.0, 1.0)
    cutoff_deg: float = 30.0
    name: str = "light"
    radius: float = field(default=1.0, metadata=_OPTIONAL)
    file: str = field(default="", metadata=_OPTIONAL)
    sha256: str = field(default="", metadata=_OPTIONAL)
    channel: int = field(default=0, metadata=_OPTIONAL)
    rotation: tuple[float, ...] = field(default=IDENTITY_ROTATION, metadata=_OPTIONAL)


def unknown_light_kind(kind: object) -> str:
    """The message for a light kind not in :data:`LIGHT_KINDS`, with a did-you-mean.

    >>> unknown_light_kind("spto")
    "unknown light kind 'spto'; expected one of point, spot, area, directional, sky, sphere, envmap (did you mean 'spot'?)"
    """
    return f"unknown light kind {kind!r}; expected one of {', '.join(LIGHT_KINDS)}" + did_you_mean(
        str(kind), LIGHT_KINDS
    )


def make_light(
    kind: LightKind, spectrum: str, power: float, *, name: str = "light", **placement: Any
) -> Light:
    """A :class:`Light` of *kind* with only the placement fields its kind uses
    (:data:`LIGHT_FIELDS`) taken from *placement*; the others keep their defaults, so saved
    scenes and records stay tidy.

    >>> make_light("point", "cie:D65", 1.0, position=(0, 0, 2), direction=(1, 0, 0)).direction
    (0.0, 0.0, -1.0)
    """
    unknown = set(placement) - set(LIGHT_PLACEMENT)
    if unknown:
        raise TypeError(
            f"make_light: unknown placement field(s) {sorted(unknown)}; "
            f"expected some of {list(LIGHT_PLACEMENT)}"
        )
    used = {k: v for k, v in placement.items() if k in LIGHT_FIELDS[kind]}
    return Light(kind=kind, spectrum=spectrum, power=power, name=name, **used)


def light_power(
    kind: str,
    position: np.ndarray,
    direction: np.ndarray,
    focus: np.ndarray,
    size: tuple[float, float],
    irradiance: float,
) -> float:
    """:attr:`Light.power` delivering *irradiance* at *focus* on a surface facing the light.

    Inverse square law for point and spot lights (power ``E d²``, a radiant intensity); an
    area light of radiance L and area A gives about ``L A cos θ / d²`` (cos θ of its normal
    *direction* towards *focus*, at least 0.2); a directional light's power is the irradiance, a sky's the irradiance over π.
    Positions in scene units, *direction* a unit vector; relative radiometric units.

    >>> light_power("point", np.zeros(3), np.array([0, 0, 1.0]), np.array([0, 0, 2.0]), (1, 1), 1.0)
    4.0
    """
    if kind == "sky":
        return irradiance / math.pi  # a uniform sky of radiance L gives E = π L
    if "position" not in LIGHT_FIELDS[kind]:
        return irradiance
    offset = focus - np.asarray(position, float)
    d2 = float(offset @ offset)
    if "size" in LIGHT_FIELDS[kind]:
        cos_light = float(direction @ offset) / math.sqrt(d2)
        return irradiance * d2 / (size[0] * size[1] * max(cos_light, 0.2))
    return irradiance * d2


@dataclass(frozen=True)
class Camera:
    """A pinhole camera.

    Attributes
    ----------
    origin, target, up
        World-space eye position, look-at point and up vector.
    fov_deg
        Horizontal field of view in degrees.
    width, height
        Image size in pixels.
    """

    origin: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    fov_deg: float = 40.0
    width: int = 128
    height: int = 128
    name: str = "view0"


@dataclass(frozen=True)
class Scene:
    """A complete renderable scene: geometry, materials, lights and one camera."""

    name: str
    meshes: tuple[Mesh, ...]
    materials: tuple[Material, ...]
    lights: tuple[Light, ...]
    camera: Camera
    metadata: dict[str, Any] = field(default_factory=dict, compare=False, hash=False)

    @property
    def textured(self) -> bool:
        """Whether a mesh carries a spectral texture."""
        return any(m.texture is not None for m in self.meshes)


def record_fields(record: Any) -> dict[str, Any]:
    """The fields of dataclass *record* that its plain record keeps: all but those marked
    ``omit_default`` at their default and those whose ``omit_when(record)`` holds (a procedural
    texture's weights). The one rule of :func:`scene_to_dict` and of the sample files' JSON
    (:func:`spectrinsic.gt_export.sample.plain_data`)."""
    return {
        f.name: getattr(record, f.name)
        for f in fields(record)
        if not (f.metadata.get("omit_default") and getattr(record, f.name) == f.default)
        and not f.metadata.get("omit_when", lambda record: False)(record)
    }


def _plain(value: Any) -> Any:
    if is_dataclass(value) and not isinstance(value, type):
        return {k: _plain(v) for k, v in record_fields(value).items()}
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, np.generic):
        return value.item()
    return value


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """Return *scene* as JSON-serialisable plain data (arrays become nested lists)."""
    return _plain(scene)


def _record(entry: Mapping[str, Any]) -> dict[str, Any]:
    """A record's fields from plain data: lists back to the tuples the frozen records hold."""
    return {str(k): tuple(v) if isinstance(v, list) else v for k, v in entry.items()}


def _mesh_from_dict(m: Mapping[str, Any]) -> Mesh:
    return Mesh(
        name=str(m["name"]),
        vertices=np.asarray(m["vertices"], np.float64).reshape(-1, 3),
        faces=np.asarray(m["faces"], np.int64).reshape(-1, 3),
        face_materials=np.asarray(m["face_materials"], np.int64).reshape(-1),
        object_id=int(m["object_id"]),
        texture=texture_from_record(m["texture"]) if m.get("texture") else None,
        semantic=str(m.get("semantic") or ""),
        maps=maps_from_record(m["maps"]) if m.get("maps") else None,
    )


def scene_from_dict(data: Mapping[str, Any]) -> Scene:
    """The :class:`Scene` of its :func:`scene_to_dict` record, the inverse:
    ``scene_from_dict(scene_to_dict(s)) == s`` (fields left out at their defaults come back as
    those defaults; a procedural texture's weights from its recipe). Raises
    :class:`~spectrinsic.errors.SceneError` (one line) on any other structure.

    >>> s = scene_from_dict({"name": "s", "meshes": [], "materials": [{"name": "m",
    ...     "spectrum": "flat:0.5"}], "lights": [], "camera": {"origin": [0, 0, 1],
    ...     "target": [0, 0, 0]}})
    >>> s.materials[0].kind, s.camera.width
    ('diffuse', 128)
    """
    try:
        return Scene(
            str(data["name"]),
            tuple(_mesh_from_dict(m) for m in data["meshes"]),
            tuple(Material(**_record(m)) for m in data["materials"]),
            tuple(Light(**_record(x)) for x in data["lights"]),
            Camera(**_record(data["camera"])),
            dict(data.get("metadata") or {}),
        )
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise SceneError(
            f"scene record: unexpected structure ({type(exc).__name__}: {exc})"
        ) from exc


def scene_hash(scene: Scene) -> str:
    """SHA-256 of the scene's canonical JSON (metadata excluded): equal scenes, equal hashes."""
    return scene_record_hash(scene_to_dict(scene))


def scene_record_hash(data: Mapping[str, Any]) -> str:
    """:func:`scene_hash` of a scene record (:func:`scene_to_dict`'s output, e.g. with its
    ``csv:`` names made portable as a sample writes them)."""
    record = {k: v for k, v in data.items() if k != "metadata"}
    blob = json.dumps(record, sort_keys=True, separators=(",", ":")).encode()
    return hashlib.sha256(blob).hexdigest()
