"""Scene validation with one-line errors naming the source (file or scene) and the field.

:func:`validate_scene` checks what a renderer would otherwise silently get wrong:

- structure: array shapes and dtypes, finite vertices (no NaN), face and material indices in
  range, unique mesh names, positive image size, a field of view in (0, 180) degrees;
- spectra: every material names a known *reflectance* (and a tinted glass's transmittance is
  one too, a fraction in [0, 1]) and every light a known *illuminant*
  (:func:`spectrinsic.spectra.get_spectrum`, whose did-you-mean suggestions are kept);
- physics: light power > 0; and, unless asked not to, the placement of the camera and the
  lights (:func:`spectrinsic.scenes.placement.check_placement`: nothing inside a closed mesh,
  a camera that sees a mesh), run once the geometry is sound.

Problems of independent parts are reported together (:class:`~spectrinsic.scenes.problems.Problems`).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SpectrinsicError, with_article
from ..spectra import get_spectrum
from .envmaps import check_envmaps
from .materials import material_problem
from .model import GLASS_TINTS, LIGHT_FIELDS, LIGHT_KINDS, Scene, unknown_light_kind
from .placement import check_placement as _check_placement  # the keyword below has its name
from .problems import Problems, field_error
from .semantic import SEMANTIC_CLASSES
from .surface_maps import maps_problem
from .textures import texture_problem

__all__ = [
    "validate_scene",
    "check_classes",
    "POWER_RANGE",
    "MAX_COORDINATE",
]


#: A light's power, in the scene's relative units, must lie in this closed range: the renderer
#: carries power × spectrum (unit luminance-weighted mean) × geometry in float32 (largest
#: 3.4e38, smallest normal 1.2e-38), so 1e±20 leaves 18 orders of magnitude for the spectrum's
#: peak, the distance falloff and the sampling weights; a light below it is negligible (it
#: would underflow to black, and alone gives Mitsuba an emitter with no probability mass).
POWER_RANGE = (1e-20, 1e20)
#: Largest absolute coordinate (vertices, light positions and directions, camera) in scene
#: units: vertices are cast to float32 (largest 3.4e38) and squared distances must stay finite.
MAX_COORDINATE = 1e18


def _check_materials(scene: Scene, source: str) -> None:
    """Gloss parameters of every material (:func:`~spectrinsic.scenes.materials.material_problem`)."""
    for i, mat in enumerate(scene.materials):
        problem = material_problem(mat)
        if problem:
            raise field_error(source, f"materials[{i}] ({mat.name!r})", problem)


def _vec(value: object, n: int = 3) -> np.ndarray | None:
    """*value* as ``n`` finite numbers of magnitude <= :data:`MAX_COORDINATE`, else ``None``."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        return None
    if arr.shape != (n,) or not np.all(np.abs(arr) <= MAX_COORDINATE):
        return None
    return arr


def _check_spectrum(
    source: str, field: str, name: object, kind: str, data_dir: str | None, cache: dict[str, object]
) -> None:
    if not isinstance(name, str) or not name:
        raise field_error(source, field, f"expected a spectrum name string, got {name!r}")
    if name not in cache:
        try:
            cache[name] = get_spectrum(name, data_dir=data_dir)
        except SpectrinsicError as exc:
            cache[name] = exc
    found = cache[name]
    if isinstance(found, SpectrinsicError):
        raise field_error(source, field, str(found)) from found
    found_kind = getattr(found, "kind", kind)
    if found_kind != kind:
        raise field_error(
            source,
            field,
            f"{name!r} is {with_article(found_kind)} spectrum; expected {with_article(kind)}",
        )


def _check_area(v: np.ndarray, f: np.ndarray, source: str, where: str) -> None:
    """A mesh needs a face of non-zero area (all-degenerate faces give no surface, and no
    normal to shade with)."""
    tri = v.astype(np.float64)[f]
    if not np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).any():
        raise field_error(
            source,
            f"{where}.faces",
            f"all {len(f)} faces have zero area (collinear "
            "or repeated vertices); the mesh has no surface to render",
        )


def _check_coordinates(v: np.ndarray, source: str, where: str) -> None:
    """Vertices finite and within ±:data:`MAX_COORDINATE` (finite once cast to float32)."""
    bad = ~np.isfinite(v).all(axis=1)
    if bad.any():
        raise field_error(
            source,
            f"{where}.vertices",
            f"{int(bad.sum())} vertices are NaN or infinite (first: vertex {int(np.argmax(bad))})",
        )
    far = ~(np.abs(v.astype(np.float64)) <= MAX_COORDINATE).all(axis=1)
    if far.any():
        raise field_error(
            source,
            f"{where}.vertices",
            f"{int(far.sum())} vertices have a coordinate beyond ±{MAX_COORDINATE:g} "
            f"(first: vertex {int(np.argmax(far))}); float32 rendering needs smaller ones",
        )


def _check_meshes(scene: Scene, source: str) -> None:
    if not scene.meshes:
        raise field_error(source, "meshes", "a scene needs at least one mesh")
    seen: set[str] = set()
    n_mat = len(scene.materials)
    for i, m in enumerate(scene.meshes):
        where = f"meshes[{i}] ({m.name!r})"
        if not isinstance(m.name, str) or not m.name:
            raise field_error(
                source, f"meshes[{i}].name", f"expected a non-empty string, got {m.name!r}"
            )
        if m.name in seen:
            raise field_error(source, f"{where}.name", "duplicate mesh name; names must be unique")
        seen.add(m.name)
        v, f, fm = np.asarray(m.vertices), np.asarray(m.faces), np.asarray(m.face_materials)
        if v.ndim != 2 or v.shape[1] != 3 or not np.issubdtype(v.dtype, np.number) or len(v) < 3:
            raise field_error(
                source,
                f"{where}.vertices",
                f"expected a (V>=3, 3) float array, got shape {v.shape}",
            )
        _check_coordinates(v, source, where)
        if f.ndim != 2 or f.shape[1] != 3 or len(f) == 0 or not np.issubdtype(f.dtype, np.integer):
            raise field_error(
                source,
                f"{where}.faces",
                f"expected a (F>=1, 3) integer array, got {f.dtype} {f.shape}",
            )
        if f.min() < 0 or f.max() >= len(v):
            raise field_error(
                source, f"{where}.faces", f"vertex index out of range 0..{len(v) - 1}"
            )
        _check_area(v, f, source, where)
        if fm.shape != (len(f),) or not np.issubdtype(fm.dtype, np.integer):
            raise field_error(
                source,
                f"{where}.face_materials",
                f"expected ({len(f)},) integers, got {fm.dtype} {fm.shape}",
            )
        if fm.min() < 0 or fm.max() >= n_mat:
            raise field_error(
                source, f"{where}.face_materials", f"material index out of range 0..{n_mat - 1}"
            )
        # ids are stored as 32-bit integers (int32 bits in an EXR UINT channel, -1 background)
        if not isinstance(m.object_id, (int, np.integer)) or not 0 <= m.object_id < 2**31:
            raise field_error(
                source,
                f"{where}.object_id",
                f"expected an integer from 0 to 2**31 - 1, got {m.object_id!r}",
            )


def check_classes(scene: Scene, source: str) -> None:
    """Every mesh's class is in the table, and meshes sharing an object id share it (the
    semantic layer is read through the object-id layer)."""
    classes: dict[int, str] = {}
    for i, m in enumerate(scene.meshes):
        where = f"meshes[{i}] ({m.name!r}).semantic"
        if m.semantic not in SEMANTIC_CLASSES:
            raise field_error(source, where, f"expected one of {', '.join(SEMANTIC_CLASSES)}")
        other = classes.setdefault(int(m.object_id), m.semantic)
        if other != m.semantic:
            why = f"meshes sharing an object id share a class (object {m.object_id}: {other!r})"
            raise field_error(source, where, f"{m.semantic!r}; {why}")


def _check_textures(scene: Scene, source: str) -> None:
    kinds = [m.kind for m in scene.materials]
    for i, m in enumerate(scene.meshes):
        problem = None if m.texture is None else texture_problem(m.texture, m.face_materials, kinds)
        if problem is not None:
            raise field_error(source, f"meshes[{i}] ({m.name!r}).texture", problem)
        problem = None if m.maps is None else maps_problem(m.maps, len(m.faces))
        if problem is None and m.maps is not None and m.maps.masked:
            problem = _masked_tint(scene, m.face_materials)
        if problem is not None:
            raise field_error(source, f"meshes[{i}] ({m.name!r}).maps", problem)


def _masked_tint(scene: Scene, face_materials: np.ndarray) -> str | None:
    """Why a masked mesh of *face_materials* is refused: tinted glass among them (the band
    path cannot tell a mask's hole from a transmission through glass, and would tint it)."""
    n = len(scene.materials)
    tinted = [
        scene.materials[j].name
        for j in np.unique(face_materials)
        if 0 <= j < n and scene.materials[j].tinted
    ]
    return f"an opacity mask on tinted glass {tinted[0]!r} is not supported" if tinted else None


def _check_power(power: object, source: str, field: str) -> None:
    """A light's power: a finite number in :data:`POWER_RANGE`."""
    if isinstance(power, bool) or not isinstance(power, (int, float, np.floating, np.integer)):
        raise field_error(source, field, f"expected a number, got {power!r}")
    if not math.isfinite(power) or power <= 0:
        raise field_error(source, field, f"must be a finite number > 0, got {power!r}")
    lo, hi = POWER_RANGE
    if not lo <= power <= hi:
        raise field_error(
            source,
            field,
            f"{power!r} is outside [{lo:g}, {hi:g}] (a negligible or overflowing light "
            "in float32 rendering)",
        )


def _check_lights(scene: Scene, source: str) -> None:
    if not scene.lights:  # say what --approximate left out (say, a .blend's World)
        changed = "; ".join(scene.metadata.get("approximated") or ())
        why = f" (--approximate: {changed})" if changed else ""
        raise field_error(source, "lights", f"a scene needs at least one light{why}")
    for i, light in enumerate(scene.lights):
        where = f"lights[{i}]"
        if light.kind not in LIGHT_KINDS:
            raise field_error(source, f"{where}.kind", unknown_light_kind(light.kind))
        _check_power(light.power, source, f"{where}.power")
        if _vec(light.position) is None:
            raise field_error(
                source,
                f"{where}.position",
                f"expected 3 finite numbers within ±{MAX_COORDINATE:g}, got {light.position!r}",
            )
        uses = LIGHT_FIELDS[light.kind]
        if "direction" in uses:
            d = _vec(light.direction)
            if d is None or np.linalg.norm(d) == 0:
                raise field_error(
                    source,
                    f"{where}.direction",
                    f"expected a non-zero 3-vector, got {light.direction!r}",
                )
        if "size" in uses:
            s = _vec(light.size, 2)
            if s is None or np.any(s <= 0):
                raise field_error(
                    source, f"{where}.size", f"expected (width, height) > 0, got {light.size!r}"
                )
        if "radius" in uses and not (math.isfinite(light.radius) and light.radius > 0):
            raise field_error(
                source, f"{where}.radius", f"expected a radius > 0, got {light.radius!r}"
            )
        if "cutoff_deg" in uses and not 0 < light.cutoff_deg <= 90:
            raise field_error(
                source,
                f"{where}.cutoff_deg",
                f"expected a cone half-angle in (0, 90], got {light.cutoff_deg!r}",
            )


def _check_envmaps(scene: Scene, source: str) -> None:
    problem = check_envmaps(scene)
    if problem is not None:
        raise field_error(source, "lights", problem)


def _check_camera(scene: Scene, source: str) -> None:
    cam = scene.camera
    for attr in ("origin", "target", "up"):
        if _vec(getattr(cam, attr)) is None:
            raise field_error(
                source,
                f"camera.{attr}",
                f"expected 3 finite numbers within ±{MAX_COORDINATE:g}, got {getattr(cam, attr)!r}",
            )
    forward = np.asarray(cam.target, float) - np.asarray(cam.origin, float)
    if np.linalg.norm(forward) == 0:
        raise field_error(
            source, "camera.target", "equals camera.origin; the camera has no viewing direction"
        )
    up = np.asarray(cam.up, float)
    up_norm = float(np.linalg.norm(up))
    if (
        up_norm == 0
        or np.linalg.norm(np.cross(forward / np.linalg.norm(forward), up)) < 1e-6 * up_norm
    ):
        raise field_error(
            source, "camera.up", f"{list(cam.up)} is zero or parallel to the viewing direction"
        )
    if not isinstance(cam.fov_deg, (int, float, np.number)) or not 0 < cam.fov_deg < 180:
        raise field_error(
            source,
            "camera.fov_deg",
            f"expected a horizontal field of view in (0, 180) degrees, got {cam.fov_deg!r}",
        )
    for attr in ("width", "height"):
        value = getattr(cam, attr)
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise field_error(
                source, f"camera.{attr}", f"expected a positive integer pixel count, got {value!r}"
            )


def validate_scene(
    scene: Scene,
    *,
    source: str | None = None,
    data_dir: str | None = None,
    check_spectra: bool = True,
    check_placement: bool = True,
) -> Scene:
    """Check *scene* and return it unchanged, or raise a one-line :class:`SceneError`.

    Parameters
    ----------
    scene
        The scene to check.
    source
        What to name in messages (the scene file's path); default ``"scene '<name>'"``.
    data_dir
        Spectral data directory for spectra that need one (``sfu:...``).
    check_spectra
        Resolve every spectrum name (needs the spectral registries).
    check_placement
        Run the geometric tests (lights/camera inside closed meshes, camera sees geometry).

    Raises
    ------
    SceneError
        ``"<source>: <field>: <problem>"``, e.g.
        ``"room.yaml: lights[1].power: must be a finite number > 0, got 0.0"``; several
        problems of independent parts (meshes, lights, camera, each spectrum) are listed in
        the one line.
    """
    source = source or f"scene {scene.name!r}"
    problems = Problems(source)
    for check in (
        _check_meshes,
        check_classes,
        _check_lights,
        _check_camera,
        _check_materials,
        _check_textures,
        _check_envmaps,
    ):
        problems.get(check, scene, source)
    if check_spectra:
        cache: dict[str, object] = {}
        for i, mat in enumerate(scene.materials):
            problems.get(
                _check_spectrum,
                source,
                f"materials[{i}] ({mat.name!r}).spectrum",
                mat.spectrum,
                "reflectance",
                data_dir,
                cache,
            )
            for key in (k for k in GLASS_TINTS if getattr(mat, k)):  # fractions in [0, 1]
                problems.get(
                    _check_spectrum,
                    source,
                    f"materials[{i}] ({mat.name!r}).{key}",
                    getattr(mat, key),
                    "reflectance",
                    data_dir,
                    cache,
                )
        for i, light in enumerate(scene.lights):
            problems.get(
                _check_spectrum,
                source,
                f"lights[{i}].spectrum",
                light.spectrum,
                "illuminant",
                data_dir,
                cache,
            )
    if check_placement and not problems.messages:  # placement needs sound geometry
        problems.get(_check_placement, scene, source)
    problems.raise_if_any()
    return scene
