"""Ground-truth layers computed from a render result and the scene's spectra (pure functions).

Nothing here reads or writes files or touches a renderer: inputs are a :class:`Scene` (which
names every spectrum) and a *RenderResult-like* record with the attributes ``images``, ``raw``,
``per_light``, ``aovs`` and ``meta`` described in CONTRACTS.md.

Colour conventions (thesis chapter 4, Eq. 4.9–4.16). For sensor curves ``S`` (sRGB = the
IEC 61966-2-1 matrix applied to the CIE 1931 CMFs, or a camera), the *canonical response* of a
reflectance ``ρ`` under an illuminant ``E`` is

    p(ρ; E, S) = ∫ ρ E S dλ / ∫ E ȳ dλ,

so the perfect white has luminance 1 under any light, and under D65 with sRGB sensors
``p = p^{s,c}`` is the absolute reflectance of :func:`spectrinsic.spectra.absolute_reflectance`
(white = (1, 1, 1) up to the 1 nm integration of D65). Camera curves are first scaled by one
factor so that the mean channel of the perfect white under D65 is 1 (white balance is left to
the camera, as the thesis' relative reflectance ``S_Sen · I^a`` keeps it). Every integral uses
the 1 nm CIE grid (360–830 nm).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from spectrinsic.errors import DatasetError
from spectrinsic.scenes.model import Scene

# Responses with the light's white at Y = 1; under D65 with sRGB sensors, the canonical p^{s,c}.
from spectrinsic.spectra import white_normalised_responses as canonical_responses

__all__ = [
    "Layer",
    "LightRecord",
    "GroundTruth",
    "REFERENCE_MODES",
    "DEFAULT_CUBE_SENSORS",
    "REFLECTANCE_FLOOR",
    "compute_ground_truth",
    "reference_mode",
    "canonical_responses",
    "camera_curves",
    "cube_to_sensors",
    "coverage_weighted",
    "shading_from",
    "luminance",
    "relative_error_map",
    "illuminant_map",
    "light_shares",
    "photometric_matrices",
]

log = logging.getLogger(__name__)

#: Render modes in order of preference for the reference ``image``: the 31-band cube shares
#: its light paths with the 3- and 6-sensor passes (differences are purely spectral), the
#: spectral Monte Carlo render is unbiased but noisier.
REFERENCE_MODES: tuple[str, ...] = ("bands31", "spectral", "rgb6", "rgb3")
#: Sensor set assumed for ``raw["bands31"]`` when the render metadata does not name one.
DEFAULT_CUBE_SENSORS = "bands:31@400-700"
#: |reflectance| at or below this (per channel) has no defined shading (shading stored as 0).
REFLECTANCE_FLOOR = 1e-6
#: Error maps are 0 where the reference colour norm is below this fraction of its 99th percentile.
ERROR_FLOOR = 1e-3
#: Training reflectances of the photometric matrices (thesis section 4.4 uses Munsell chips).
TRAINING_FAMILY = "munsell"


@dataclass(frozen=True)
class Layer:
    """One ground-truth layer.

    Attributes
    ----------
    name
        Loader key, e.g. ``"reflectance"`` or ``"image_camera/Nikon 5100 (NPL)"``.
    data
        ``(H, W)`` or ``(H, W, C)`` float32.
    channels
        Channel names in order (``("R", "G", "B")``, ``("Z",)``...).
    units
        Units and encoding, in words.
    group
        File stem the layer is written to (``"image"``, ``"intrinsics"``, ``"geometry"``,
        ``"camera-<slug>"``, ``"cube"``).
    nonnegative
        Whether negative values are invalid (checked by :func:`spectrinsic.gt_export.check_dataset`).
    """

    name: str
    data: np.ndarray = field(repr=False)
    channels: tuple[str, ...]
    units: str
    group: str
    nonnegative: bool = False


@dataclass(frozen=True)
class LightRecord:
    """What ground truth says about one light: its SPD and colour in every sensor space."""

    index: int
    name: str
    kind: str
    spectrum: str
    power: float
    position: tuple[float, ...]
    direction: tuple[float, ...]
    size: tuple[float, ...]
    cutoff_deg: float
    #: CIE 1931 xy chromaticity.
    xy: tuple[float, ...]
    #: Linear sRGB colour at unit luminance (Y = 1).
    srgb: tuple[float, ...]
    #: Camera colours at unit luminance, per camera name (camera curves as in the module doc).
    camera: dict[str, tuple[float, ...]]
    #: Fraction of the image's luminance due to this light (from the per-light renders).
    share: float


@dataclass(frozen=True)
class GroundTruth:
    """Every layer and the per-sample records written to ``meta.json``."""

    layers: dict[str, Layer]
    lights: tuple[LightRecord, ...]
    materials: dict[str, str]
    matrices: dict[str, Any]
    reference_mode: str
    cameras: tuple[str, ...]
    cube_sensors: str | None


# ----------------------------------------------------------------------------------------------
# Spectral helpers


def _grid() -> np.ndarray:
    from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS

    return COLORIMETRIC_WAVELENGTHS


def camera_curves(name: str, wavelengths: np.ndarray, *, data_dir: Any = None) -> np.ndarray:
    """``(3, W)`` sensitivities of camera *name* on *wavelengths*, scaled so that the perfect
    white under D65 has mean channel 1 in :func:`canonical_responses` (one factor for all
    channels: the camera's own white balance is kept)."""
    from spectrinsic.spectra import get_sensors, get_spectrum

    curves = get_sensors(name, data_dir=data_dir).on(wavelengths)
    d65 = get_spectrum("cie:D65").on(wavelengths)
    white = canonical_responses(np.ones(wavelengths.size), d65, curves, wavelengths)
    if not white.mean() > 0:
        raise DatasetError(f"camera {name!r} has no response to D65 on 360-830 nm")
    return curves / white.mean()


def cube_to_sensors(cube_sensors: np.ndarray, curves: np.ndarray, wavelengths: np.ndarray) -> np.ndarray:
    """``(K, B)`` weights ``A`` with ``S ≈ A @ bands`` (least squares on *wavelengths*).

    A band cube with values ``∫ L B_b dλ`` then gives ``∫ L S_k dλ ≈ Σ_b A_kb cube_b``; for
    disjoint box bands ``A_kb`` is the mean of ``S_k`` over band ``b``. Light outside the
    bands' support is not seen.
    """
    from spectrinsic.spectra.grid import integration_weights

    w = integration_weights(wavelengths)
    gram = (cube_sensors * w) @ cube_sensors.T
    cross = (curves * w) @ cube_sensors.T
    return np.linalg.solve(gram.T, cross.T).T


def _training_reflectances(wavelengths: np.ndarray) -> np.ndarray:
    from spectrinsic.spectra import family_values

    return family_values(TRAINING_FAMILY, wavelengths)


def photometric_matrices(
    illuminants: Mapping[str, np.ndarray],
    sensor_spaces: Mapping[str, np.ndarray],
    wavelengths: np.ndarray,
    *,
    training: np.ndarray | None = None,
) -> dict[str, Any]:
    """Fit ``S_Sen`` per camera and ``L_CLig`` per illuminant and sensor space (thesis 4.2–4.4).

    Following section 4.4.1, over the training reflectances (1269 Munsell chips):
    ``p^{s,c}`` are canonical responses under D65 with sRGB sensors, ``p^c`` under D65 with a
    camera, ``p`` under the scene illuminant with that camera; ``S_Sen`` is the least-squares
    3×3 with ``p^c ≈ S_Sen p^{s,c}`` and ``L_CLig`` the one with ``p ≈ L_CLig p^c``
    (Eq. 4.11, 4.13; matrices act on column vectors).

    Parameters
    ----------
    illuminants
        ``{label: (W,) SPD}``, e.g. ``{"scene": ..., "light 0": ...}``.
    sensor_spaces
        ``{name: (3, W) curves}``; must contain ``"srgb"``.

    Returns
    -------
    dict
        ``{"S_Sen": {camera: 3×3 list}, "L_CLig": {space: {label: 3×3 list}},
        "L_CLig_diagonal": {...}}`` (the diagonal fits are the von Kries models of SC2/SC3).
    """
    from spectrinsic.spectra import fit_matrix, get_spectrum

    rho = _training_reflectances(wavelengths) if training is None else training
    d65 = get_spectrum("cie:D65").on(wavelengths)
    canon = {k: canonical_responses(rho, d65, s, wavelengths) for k, s in sensor_spaces.items()}
    out: dict[str, Any] = {"S_Sen": {}, "L_CLig": {}, "L_CLig_diagonal": {}}
    for space, curves in sensor_spaces.items():
        if space != "srgb":
            out["S_Sen"][space] = fit_matrix(canon["srgb"], canon[space]).tolist()
        full, diag = {}, {}
        for label, spd in illuminants.items():
            p = canonical_responses(rho, spd, curves, wavelengths)
            full[label] = fit_matrix(canon[space], p).tolist()
            diag[label] = np.diag(fit_matrix(canon[space], p, diagonal=True)).tolist()
        out["L_CLig"][space] = full
        out["L_CLig_diagonal"][space] = diag
    return out


# ----------------------------------------------------------------------------------------------
# Image-space helpers


def luminance(rgb: np.ndarray) -> np.ndarray:
    """CIE Y of linear sRGB ``(..., 3)`` -> ``(...)``."""
    from spectrinsic.spectra import LINEAR_SRGB_TO_XYZ

    return np.asarray(rgb, float) @ LINEAR_SRGB_TO_XYZ[1]


def coverage_weighted(coverage: np.ndarray, colours: np.ndarray) -> np.ndarray:
    """``Σ_m coverage[..., m] · colours[m]``: box-filtered (anti-aliased) per-pixel colour.

    Parameters
    ----------
    coverage
        ``(H, W, M)`` fraction of each pixel covered by material m (background: all 0).
    colours
        ``(M, C)`` colour of each material.

    Returns
    -------
    ``(H, W, C)`` float64.
    """
    coverage = np.asarray(coverage, float)
    colours = np.asarray(colours, float)
    if coverage.shape[-1] != colours.shape[0]:
        raise DatasetError(
            f"coverage has {coverage.shape[-1]} materials but the scene has {colours.shape[0]}"
        )
    return coverage @ colours


def shading_from(image: np.ndarray, reflectance: np.ndarray) -> np.ndarray:
    """Shading-illumination ``image / reflectance`` per channel (thesis Fig. 5.8).

    Where ``|reflectance| <= REFLECTANCE_FLOOR`` (background, black) shading is 0; elsewhere
    ``image = reflectance ∘ shading`` holds to float precision. Same shape as *image*.
    """
    image = np.asarray(image, float)
    reflectance = np.asarray(reflectance, float)
    valid = np.abs(reflectance) > REFLECTANCE_FLOOR
    return np.where(valid, image / np.where(valid, reflectance, 1.0), 0.0)


def relative_error_map(approx: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Per-pixel ``‖p̂ − p‖₂ / ‖p‖₂`` over channels (the ε of thesis Table 5.2).

    Pixels whose reference norm is below ``ERROR_FLOOR`` times its 99th percentile get 0.
    Returns ``(H, W)`` float64.
    """
    approx = np.asarray(approx, float)
    reference = np.asarray(reference, float)
    norm = np.linalg.norm(reference, axis=-1)
    positive = norm[norm > 0]
    floor = ERROR_FLOOR * np.percentile(positive, 99) if positive.size else np.inf
    valid = norm > floor
    err = np.linalg.norm(approx - reference, axis=-1)
    return np.where(valid, err / np.where(valid, norm, 1.0), 0.0)


def light_shares(per_light_y: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
    """Fraction of the image luminance due to each light, ``(L,)`` summing to 1.

    *per_light_y* is ``(L, H, W)`` luminance of each light's render; restricted to *mask*.
    """
    y = np.clip(np.asarray(per_light_y, float), 0.0, None)
    if mask is not None:
        y = y[:, mask]
    totals = y.reshape(y.shape[0], -1).sum(axis=1)
    total = totals.sum()
    if not total > 0:
        return np.full(y.shape[0], 1.0 / y.shape[0])
    return totals / total


def _shares_paths(mode: str, reference: str) -> bool:
    """Whether two render modes trace the same light paths (both K-channel diagonal passes of
    one scene, same seed and spp), so that their per-pixel difference is purely spectral."""
    from spectrinsic.render.modes import RENDER_MODES

    return all(m in RENDER_MODES and RENDER_MODES[m].kind == "diagonal" for m in (mode, reference))


def illuminant_map(per_light_y: np.ndarray, colours: np.ndarray) -> np.ndarray:
    """Per-pixel colour of the light arriving: luminance-share-weighted light colours.

    ``E(x) = Σ_l w_l(x) c_l`` with ``w_l(x) = Y_l(x) / Σ_k Y_k(x)``, where ``Y_l`` is the
    luminance of light l's own render (direct and indirect light it causes) and ``c_l`` its
    colour at unit luminance. As every light's render shares the same reflectance at x, ``w_l``
    is light l's share of the light arriving there. ``E`` has luminance 1 where any light
    arrives and is 0 where none does.

    Parameters
    ----------
    per_light_y
        ``(L, H, W)`` luminance of each per-light render (negative noise clipped to 0).
    colours
        ``(L, C)`` light colours at unit luminance.

    Returns
    -------
    ``(H, W, C)`` float64.
    """
    y = np.clip(np.asarray(per_light_y, float), 0.0, None)
    total = y.sum(axis=0)
    lit = total > 0
    w = np.where(lit, y / np.where(lit, total, 1.0), 0.0)
    return np.einsum("lhw,lc->hwc", w, np.asarray(colours, float))


# ----------------------------------------------------------------------------------------------
# The record accessors (duck-typed RenderResult)


def _aov(result: Any, name: str) -> np.ndarray | None:
    aovs = getattr(result, "aovs", None) or {}
    value = aovs.get(name) if isinstance(aovs, Mapping) else getattr(aovs, name, None)
    return None if value is None else np.asarray(value)


def reference_mode(result: Any) -> str:
    """The render mode whose image is the reference ``image`` (first of :data:`REFERENCE_MODES`)."""
    for mode in REFERENCE_MODES:
        if mode in result.images:
            return mode
    if result.images:
        return sorted(result.images)[0]
    raise DatasetError("render result has no images; expected at least one render mode")


def _cube_sensor_name(result: Any) -> str:
    sensors = (getattr(result, "meta", None) or {}).get("sensors")
    if isinstance(sensors, Mapping) and isinstance(sensors.get("bands31"), str):
        return sensors["bands31"]
    log.info("render meta names no sensors for 'bands31'; assuming %s", DEFAULT_CUBE_SENSORS)
    return DEFAULT_CUBE_SENSORS


def _slug(name: str) -> str:
    """File-name-safe form of a camera name: ``"camera:Nikon 5100 (NPL)"`` -> ``"nikon-5100-npl"``."""
    core = name.split(":", 1)[-1].lower()
    out = "".join(c if c.isalnum() else "-" for c in core)
    while "--" in out:
        out = out.replace("--", "-")
    return out.strip("-")


def _camera_key(name: str) -> str:
    return name.split(":", 1)[1] if name.startswith("camera:") else name


# ----------------------------------------------------------------------------------------------
# Everything together

_UNITS_IMAGE = "relative radiance (render units), linear sRGB (IEC 61966-2-1, D65 white), from CIE XYZ"
_UNITS_CAMERA = (
    "relative radiance (render units) in the camera's raw linear RGB; curves scaled so the "
    "perfect white under D65 has mean channel 1"
)


def compute_ground_truth(
    scene: Scene,
    result: Any,
    *,
    cameras: Sequence[str] = (),
    write_cube: bool = False,
    data_dir: Any = None,
    training: np.ndarray | None = None,
) -> GroundTruth:
    """Compute every ground-truth layer of one rendered sample.

    Parameters
    ----------
    scene
        The scene that was rendered (names every material and light spectrum).
    result
        RenderResult-like record (``images``, ``raw``, ``per_light``, ``aovs``, ``meta``).
    cameras
        Sensor-set names (``"camera:Nikon 5100 (NPL)"``); each adds an image integrated from
        the 31-band cube, a relative reflectance, shading and illuminant in that camera's RGB.
    write_cube
        Add the raw multispectral cube as layer ``cube``.
    training
        ``(N, 471)`` reflectances on the 1 nm grid for the matrix fits (default: all Munsell chips).

    Returns
    -------
    GroundTruth
    """
    from spectrinsic.spectra import (
        absolute_reflectance,
        get_sensors,
        get_spectrum,
        xyz_to_linear_srgb,
        xyz_to_xy,
    )

    wl = _grid()
    layers: dict[str, Layer] = {}

    def add(name: str, data: np.ndarray, channels: Sequence[str], units: str, group: str,
            nonnegative: bool = False) -> None:
        layers[name] = Layer(name, np.asarray(data, dtype=np.float32), tuple(channels), units,
                             group, nonnegative)

    rgb = ("R", "G", "B")
    # -- images: the reference, every other mode, and its error against the reference
    ref = reference_mode(result)
    ref_xyz = np.asarray(result.images[ref], float)
    height, width = ref_xyz.shape[:2]
    image = xyz_to_linear_srgb(ref_xyz)
    add("image", image, rgb, _UNITS_IMAGE + f"; render mode {ref!r}", "image")
    for mode in sorted(result.images):
        if mode == ref:
            continue
        xyz = np.asarray(result.images[mode], float)
        add(f"image_{mode}", xyz_to_linear_srgb(xyz), rgb, _UNITS_IMAGE + f"; render mode {mode!r}",
            "image")
        if not _shares_paths(mode, ref):
            continue  # independent Monte Carlo paths: the difference would be noise, not error
        add(f"error_{mode}", relative_error_map(xyz, ref_xyz), ("Y",),
            f"dimensionless ‖XYZ_{mode} − XYZ_{ref}‖₂ / ‖XYZ_{ref}‖₂ per pixel (0 where unlit)",
            "image", nonnegative=True)

    # -- geometry AOVs
    mask = _aov(result, "mask")
    mask = np.ones((height, width), bool) if mask is None else mask.astype(bool)
    material_id = _aov(result, "material_id")
    coverage = _aov(result, "coverage")
    n_mat = len(scene.materials)
    if coverage is None:
        if material_id is None:
            raise DatasetError("render result has neither a 'coverage' nor a 'material_id' AOV")
        log.warning("no coverage AOV: reflectance is not anti-aliased at edges")
        coverage = (material_id[..., None] == np.arange(n_mat)).astype(float)
    add("mask", mask, ("Y",), "1 where a surface covers the pixel centre, else 0", "geometry",
        nonnegative=True)
    for name, channels, units in (
        ("depth", ("Z",), "scene units, distance from the camera to the first hit (0: background)"),
        ("normals", ("X", "Y", "Z"), "world-space unit surface normals (0: background)"),
        ("material_id", ("id",), "index into meta['materials'], stored as float32; -1 background"),
        ("object_id", ("id",), "object id of the scene meshes, stored as float32; -1 background"),
    ):
        value = _aov(result, name)
        if value is not None:
            add(name, value, channels, units, "geometry", nonnegative=name == "depth")

    # -- absolute reflectance (exact, from the spectra) and shading-illumination
    names = [m.spectrum for m in scene.materials]
    abs_refl = absolute_reflectance(names, data_dir=data_dir) if names else np.zeros((0, 3))
    reflectance = coverage_weighted(coverage, abs_refl)
    shading = shading_from(image, reflectance)
    refl_y = luminance(reflectance)
    valid_y = refl_y > REFLECTANCE_FLOOR
    grey = np.where(valid_y, luminance(image) / np.where(valid_y, refl_y, 1.0), 0.0)
    add("reflectance", reflectance, rgb,
        "dimensionless absolute reflectance, linear sRGB under D65 (perfect white = 1); "
        "box-filtered by pixel coverage, 0 for background", "intrinsics")
    add("shading", shading, rgb,
        "shading-illumination = image / reflectance per channel (render units, linear sRGB); "
        f"0 where |reflectance| <= {REFLECTANCE_FLOOR:g}", "intrinsics")
    add("shading_grey", grey, ("Y",),
        "grey shading = Y(image) / Y(reflectance) (render units); 0 where Y(reflectance) is 0",
        "intrinsics", nonnegative=True)

    # -- sensor spaces: sRGB and each camera
    spaces: dict[str, np.ndarray] = {"srgb": get_sensors("srgb").on(wl)}
    for cam in cameras:
        spaces[cam] = camera_curves(cam, wl, data_dir=data_dir)
    d65 = get_spectrum("cie:D65").on(wl)
    material_rho = (
        np.stack([get_spectrum(n, data_dir=data_dir).on(wl) for n in names])
        if names else np.zeros((0, wl.size))
    )

    # -- lights: SPD, chromaticity, colours, shares; the illuminant map
    light_spds = [get_spectrum(light.spectrum, data_dir=data_dir).on(wl) for light in scene.lights]
    white = np.ones(wl.size)
    per_light = tuple(getattr(result, "per_light", None) or ())
    if per_light:
        if len(per_light) != len(scene.lights):
            raise DatasetError(
                f"render has {len(per_light)} per-light images but the scene has "
                f"{len(scene.lights)} lights"
            )
        y_maps = np.stack([np.asarray(pl[ref] if ref in pl else next(iter(pl.values())),
                                      float)[..., 1] for pl in per_light])
    elif len(scene.lights) == 1:
        y_maps = ref_xyz[None, ..., 1]
    else:
        raise DatasetError(
            f"scene {scene.name!r} has {len(scene.lights)} lights but the render has no "
            "per-light images; render with per_light=True"
        )
    shares = light_shares(y_maps, mask)
    colours = {
        space: np.stack([canonical_responses(white, spd, curves, wl) for spd in light_spds])
        if light_spds else np.zeros((0, 3))
        for space, curves in spaces.items()
    }
    cie = get_sensors("cie1931").on(wl)
    lights = []
    for i, light in enumerate(scene.lights):
        xy = xyz_to_xy(canonical_responses(white, light_spds[i], cie, wl))
        lights.append(LightRecord(
            index=i, name=light.name, kind=light.kind, spectrum=light.spectrum,
            power=float(light.power), position=tuple(map(float, light.position)),
            direction=tuple(map(float, light.direction)), size=tuple(map(float, light.size)),
            cutoff_deg=float(light.cutoff_deg), xy=(float(xy[0]), float(xy[1])),
            srgb=tuple(float(v) for v in colours["srgb"][i]),
            camera={_camera_key(c): tuple(float(v) for v in colours[c][i]) for c in cameras},
            share=float(shares[i]),
        ))
    add("illuminant", illuminant_map(y_maps, colours["srgb"]), rgb,
        "linear sRGB colour of the light arriving (luminance-share-weighted light colours, "
        "Y = 1 where lit, 0 where no light arrives)", "intrinsics")

    # -- cameras: image from the band cube, relative reflectance, shading, illuminant
    cube_name: str | None = None
    cube = None
    if "bands31" in getattr(result, "raw", {}):
        cube = np.asarray(result.raw["bands31"], float)
        cube_name = _cube_sensor_name(result)
    if cameras and cube is None:
        raise DatasetError(
            "camera images need the 31-band cube (render mode 'bands31'); render it or pass cameras=()"
        )
    if cube is not None:
        band_set = get_sensors(cube_name or DEFAULT_CUBE_SENSORS, data_dir=data_dir)
        if band_set.n != cube.shape[-1]:
            raise DatasetError(
                f"cube has {cube.shape[-1]} channels but its sensors {cube_name!r} have {band_set.n}"
            )
        bands_wl = band_set.wavelengths
        for cam in cameras:
            key, slug = _camera_key(cam), "camera-" + _slug(cam)
            weights = cube_to_sensors(
                band_set.curves, camera_curves(cam, bands_wl, data_dir=data_dir), bands_wl
            )
            cam_image = cube @ weights.T
            cam_refl = coverage_weighted(
                coverage, canonical_responses(material_rho, d65, spaces[cam], wl)
            )
            add(f"image_camera/{key}", cam_image, rgb, _UNITS_CAMERA, slug, nonnegative=True)
            add(f"reflectance_camera/{key}", cam_refl, rgb,
                "dimensionless relative reflectance S_Sen·I^a: camera RGB under D65 "
                "(perfect white has mean channel 1)", slug, nonnegative=True)
            add(f"shading_camera/{key}", shading_from(cam_image, cam_refl), rgb,
                "camera image / camera reflectance per channel", slug)
            # Relative to the camera's own D65 white, as reflectance_camera already holds that
            # white: on a neutral surface shading_camera = shading_grey ∘ illuminant_camera.
            d65_white = canonical_responses(white, d65, spaces[cam], wl)
            add(f"illuminant_camera/{key}", illuminant_map(y_maps, colours[cam] / d65_white), rgb,
                "camera RGB of the light arriving relative to the camera's response to D65 "
                "(D65 light = (1, 1, 1)), unit luminance where lit", slug)
        if write_cube:
            add("cube", cube, band_set.channels,
                f"band radiance ∫ L B_b dλ (render units) for the bands of {cube_name!r}", "cube",
                nonnegative=True)
    elif write_cube:
        raise DatasetError("write_cube needs the 31-band cube (render mode 'bands31')")

    # -- photometric matrices (chapter 4) for the scene's effective light and each light
    illum: dict[str, np.ndarray] = {}
    if light_spds:
        illum["scene"] = np.einsum("l,lw->w", shares, np.stack(light_spds))
        for i, spd in enumerate(light_spds):
            illum[f"light {i}"] = spd
    matrices = photometric_matrices(illum, spaces, wl, training=training) if illum else {}
    matrices["convention"] = (
        "p = M @ q on column vectors; S_Sen: canonical (D65, sRGB) -> camera under D65; "
        "L_CLig: sensor space under D65 -> under the illuminant; 'scene' is the share-weighted "
        "mix of the lights; least squares over the 1269 Munsell chips, lights at unit luminance"
    )
    matrices = {k: ({_camera_key(c): v for c, v in m.items()} if isinstance(m, dict) else m)
                for k, m in matrices.items()}

    return GroundTruth(
        layers=layers,
        lights=tuple(lights),
        materials={str(i): n for i, n in enumerate(names)},
        matrices=matrices,
        reference_mode=ref,
        cameras=tuple(cameras),
        cube_sensors=cube_name,
    )
