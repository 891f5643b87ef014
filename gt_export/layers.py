"""Ground-truth layers computed from a render result and the scene's spectra (pure functions).

Nothing here reads or writes files or touches a renderer: inputs are a :class:`Scene` (which
names every spectrum) and a :class:`RenderRecord` (a :class:`spectrinsic.render.RenderResult`
or anything with its fields). :func:`compute_ground_truth` composes one function per family of
layers: images and errors, geometry, reflectance, irradiance shading (with noise and
denoising), lights, cameras and the chapter-4 matrices.

Colour conventions (thesis chapter 4, Eq. 4.9–4.16). For sensor curves ``S`` (sRGB = the
IEC 61966-2-1 matrix applied to the CIE 1931 CMFs, or a camera), the *canonical response* of a
reflectance ``ρ`` under an illuminant ``E`` is

    p(ρ; E, S) = ∫ ρ E S dλ / ∫ E ȳ dλ,

so the perfect white has luminance 1 under any light, and under D65 with sRGB sensors
``p = p^{s,c}`` is the absolute reflectance of :func:`spectrinsic.spectra.absolute_reflectance`
(white = (1, 1, 1) up to the 1 nm integration of D65). Camera curves are first scaled by one
factor so that the mean channel of the perfect white under D65 is 1 (white balance is left to
the camera, as the thesis' relative reflectance ``S_Sen · I^a`` keeps it). Every integral uses
the 1 nm CIE grid (360–830 nm). Shading, residual and illuminant come from the spectral
irradiance (:mod:`spectrinsic.gt_export.irradiance`).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import irradiance as irr
from spectrinsic.gt_export.names import camera_slug
from spectrinsic.scenes.model import Scene

# Responses with the light's white at Y = 1; under D65 with sRGB sensors, the canonical p^{s,c}.
from spectrinsic.spectra import white_normalised_responses as canonical_responses

__all__ = [
    "RenderRecord",
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
    "shading_ratio",
    "luminance",
    "relative_error_map",
    "light_shares",
    "photometric_matrices",
    "identities",
]

log = logging.getLogger(__name__)

#: Render modes in order of preference for the reference ``image``: the 31-band cube shares
#: its light paths with the 3- and 6-sensor passes (differences are purely spectral), the
#: spectral Monte Carlo render is unbiased but noisier.
REFERENCE_MODES: tuple[str, ...] = ("bands31", "spectral", "rgb6", "gauss3", "rgb3")
#: Sensor set assumed for ``raw["bands31"]`` when the render metadata does not name one.
DEFAULT_CUBE_SENSORS = "bands:31@400-700"
#: |reflectance| at or below this (per channel) has no defined ratio shading (stored as 0).
REFLECTANCE_FLOOR = 1e-6
#: Error maps are 0 where the reference colour norm is below this fraction of its 99th percentile.
ERROR_FLOOR = 1e-3
#: Training reflectances of the photometric matrices (thesis section 4.4 uses Munsell chips).
TRAINING_FAMILY = "munsell"


class RenderRecord(Protocol):
    """What ground truth reads of a render (the fields of :class:`spectrinsic.render.RenderResult`).

    ``images`` mode -> ``(H, W, 3)`` XYZ; ``raw`` mode -> ``(H, W, K)`` raw channels;
    ``per_light`` one dict mode -> XYZ per light; ``aovs`` coverage, ids, depth, normals, mask;
    ``meta`` sensors and ``to_xyz`` per mode; ``batch_raw`` per independent batch, mode -> raw.
    """

    @property
    def images(self) -> Mapping[str, np.ndarray]: ...
    @property
    def raw(self) -> Mapping[str, np.ndarray]: ...
    @property
    def per_light(self) -> Sequence[Mapping[str, np.ndarray]]: ...
    @property
    def aovs(self) -> Mapping[str, np.ndarray]: ...
    @property
    def meta(self) -> Mapping[str, Any]: ...


@dataclass(frozen=True)
class Layer:
    """One ground-truth layer.

    Attributes
    ----------
    name
        Loader key, e.g. ``"reflectance"`` or ``"image_camera/Nikon 5100 (NPL)"``.
    data
        ``(H, W)`` or ``(H, W, C)`` float32; ids ``(H, W)`` int32.
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
    #: Names of the layers computed from the denoised white-surface radiance.
    denoised: tuple[str, ...] = ()
    #: Relative standard error per layer (``{"image": {"median", "p95", "pixels"}, ...}``),
    #: from the spread of independent batches; empty for a single batch.
    noise: dict[str, dict[str, float | int]] = field(default_factory=dict)
    #: Out-of-gamut light clipped from the sRGB shading into the residual: ``pixels``, the
    #: fraction of lit pixels with a clipped channel; ``mean``/``max``, the clipped part's norm
    #: relative to the shading's norm over those pixels.
    clipping: dict[str, float] = field(default_factory=dict)


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


def shading_ratio(image: np.ndarray, reflectance: np.ndarray) -> np.ndarray:
    """The per-channel ratio ``image / reflectance`` (thesis Fig. 5.8), layer ``shading_ratio``.

    Ill-conditioned: where a reflectance channel is near 0 (saturated colours), or the light
    arriving is not D65, it depends on the material and can reach thousands. Where
    ``|reflectance| <= REFLECTANCE_FLOOR`` (background, black) it is 0; elsewhere
    ``image = reflectance ∘ shading_ratio`` holds to float precision. Same shape as *image*.
    """
    image = np.asarray(image, float)
    reflectance = np.asarray(reflectance, float)
    valid = np.abs(reflectance) > REFLECTANCE_FLOOR
    return np.where(valid, image / np.where(valid, reflectance, 1.0), 0.0)


def relative_error_map(approx: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Per-pixel ``‖p̂ − p‖₂ / ‖p‖₂`` over channels (the ε of thesis Table 5.2, Eq. 5.7).

    :func:`spectrinsic.spectra.relative_error` with ``dark_fraction=ERROR_FLOOR``: pixels whose
    reference norm is at most ``ERROR_FLOOR`` times its 99th percentile get 0.
    Returns ``(H, W)`` float64.
    """
    from spectrinsic.spectra import relative_error

    return relative_error(approx, reference, dark_fraction=ERROR_FLOOR, fill=0.0)


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


def _camera_key(name: str) -> str:
    return name.split(":", 1)[1] if name.startswith("camera:") else name


# ----------------------------------------------------------------------------------------------
# Everything together

_UNITS_IMAGE = "relative radiance (render units), linear sRGB (IEC 61966-2-1, D65 white), from CIE XYZ"
_UNITS_CAMERA = (
    "relative radiance (render units) in the camera's raw linear RGB; curves scaled so the "
    "perfect white under D65 has mean channel 1"
)
_RGB = ("R", "G", "B")


def _layer(name: str, data: np.ndarray, channels: Sequence[str], units: str, group: str,
           nonnegative: bool = False) -> Layer:
    return Layer(name, np.asarray(data, dtype=np.float32), tuple(channels), units, group, nonnegative)


@dataclass(frozen=True, eq=False)
class _Sample:
    """What every family of layers reads: the scene, the render and the spectra on the 1 nm grid."""

    scene: Scene
    result: Any
    ref: str
    wl: np.ndarray
    material_rho: np.ndarray
    d65: np.ndarray
    data_dir: Any


def _image_layers(s: _Sample) -> list[Layer]:
    """``image`` (the reference mode), every other mode, and error maps of the modes that
    share the reference's light paths (Eq. 5.7 per pixel)."""
    from spectrinsic.spectra import xyz_to_linear_srgb

    ref_xyz = np.asarray(s.result.images[s.ref], float)
    out = [_layer("image", xyz_to_linear_srgb(ref_xyz), _RGB, _UNITS_IMAGE + f"; render mode {s.ref!r}",
                  "image")]
    for mode in sorted(m for m in s.result.images if m != s.ref):
        xyz = np.asarray(s.result.images[mode], float)
        out.append(_layer(f"image_{mode}", xyz_to_linear_srgb(xyz), _RGB,
                          _UNITS_IMAGE + f"; render mode {mode!r}", "image"))
        if _shares_paths(mode, s.ref):  # else independent paths: the difference would be noise
            out.append(_layer(
                f"error_{mode}", relative_error_map(xyz, ref_xyz), ("Y",),
                f"dimensionless ‖XYZ_{mode} − XYZ_{s.ref}‖₂ / ‖XYZ_{s.ref}‖₂ per pixel (0 where unlit)",
                "image", nonnegative=True))
    return out


_GEOMETRY = (
    ("depth", ("Z",), "scene units, distance from the camera to the first hit (0: background)"),
    ("normals", ("X", "Y", "Z"), "world-space unit surface normals (0: background)"),
    ("material_id", ("id",), "index into meta['materials'], int32 (an EXR UINT channel holding "
     "the int32 bits); -1 background"),
    ("object_id", ("id",), "object id of the scene meshes, int32 (an EXR UINT channel holding "
     "the int32 bits); -1 background"),
)
_ID_LAYERS = ("material_id", "object_id")


def _ids(name: str, value: np.ndarray) -> np.ndarray:
    """An id AOV as int32: whole numbers in [-1, 2**31 - 1] (-1 background), else an error."""
    value = np.asarray(value)
    ints = value if value.dtype.kind in "iu" else np.rint(value)
    if value.size and ((ints != value).any() or ints.min() < -1 or ints.max() >= 2**31):
        raise DatasetError(f"render AOV {name!r}: expected whole ids from -1 to 2**31 - 1")
    return ints.astype(np.int32)


def _coverage(s: _Sample, shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """``(H, W, M)`` material coverage and the ``(H, W)`` mask of the render."""
    mask = _aov(s.result, "mask")
    mask = np.ones(shape, bool) if mask is None else mask.astype(bool)
    coverage = _aov(s.result, "coverage")
    if coverage is None:
        material_id = _aov(s.result, "material_id")
        if material_id is None:
            raise DatasetError("render result has neither a 'coverage' nor a 'material_id' AOV")
        log.warning("no coverage AOV: reflectance is not anti-aliased at edges")
        coverage = (material_id[..., None] == np.arange(len(s.scene.materials))).astype(float)
    return np.asarray(coverage, float), mask


def _geometry_layers(s: _Sample, mask: np.ndarray) -> list[Layer]:
    out = [_layer("mask", mask, ("Y",), "1 where a surface covers the pixel centre, else 0",
                  "geometry", nonnegative=True)]
    for name, channels, units in _GEOMETRY:
        value = _aov(s.result, name)
        if value is None:
            continue
        if name in _ID_LAYERS:
            out.append(Layer(name, _ids(name, value), channels, units, "geometry"))
        else:
            out.append(_layer(name, value, channels, units, "geometry", nonnegative=name == "depth"))
    return out


def _white_radiance(s: _Sample, coverage: np.ndarray) -> irr.WhiteRadiance:
    """``W = E/π`` from the reference render, Eq. 1 of
    :mod:`~spectrinsic.gt_export.irradiance`, with the band albedos the renderer used."""
    from spectrinsic.render.modes import channel_values, get_mode, to_xyz_matrix
    from spectrinsic.spectra import get_sensors

    mode = get_mode(s.ref)
    sensors = (s.result.meta or {}).get("sensors", {}).get(s.ref, mode.sensors)
    albedos = channel_values(s.scene, get_sensors(sensors, data_dir=s.data_dir),
                             data_dir=s.data_dir).materials
    matrices = (s.result.meta or {}).get("to_xyz", {})
    to_xyz = (np.asarray(matrices[s.ref], float) if s.ref in matrices
              else to_xyz_matrix(mode, s.scene, data_dir=s.data_dir))
    raw = s.result.raw[s.ref] if s.ref in s.result.raw else s.result.images[s.ref]
    return irr.white_radiance(raw, coverage, albedos, to_xyz, mode=s.ref)


def _srgb_white(s: _Sample) -> np.ndarray:
    from spectrinsic.spectra import get_sensors

    return canonical_responses(np.ones(s.wl.size), s.d65, get_sensors("srgb").on(s.wl), s.wl)


def _srgb_of(w: irr.WhiteRadiance) -> np.ndarray:
    from spectrinsic.spectra import xyz_to_linear_srgb

    return xyz_to_linear_srgb(w.xyz())


def _shading_set(
    w: irr.WhiteRadiance, colour: np.ndarray, white: np.ndarray, image: np.ndarray,
    reflectance: np.ndarray, *, names: tuple[str, ...], group: str, space: str,
) -> list[Layer]:
    """``shading``, ``residual`` and, if a third name is given, ``illuminant`` of one sensor
    space from ``W``'s colour."""
    shading = irr.relative_shading(colour, white, w.valid)
    grey = irr.luminance_of(w)
    layers = [
        _layer(names[0], shading, _RGB,
               f"shading-illumination: {space} of the light a perfect white would reflect here "
               "(render units, relative to that space's white under D65; ≥ 0, 0 where no surface)",
               group, nonnegative=True),
        _layer(names[1], irr.residual(image, reflectance, shading), _RGB,
               "image − reflectance ∘ shading (render units): spectral non-commutativity and "
               "out-of-gamut light; the image itself where no surface", group),
    ]
    if len(names) > 2:
        layers.append(_layer(names[2], irr.unit_luminance(shading, grey), _RGB,
                             f"{space} colour of the light arriving at unit luminance "
                             "(D65 = (1, 1, 1)); 0 where none arrives", group, nonnegative=True))
    return layers


def _intrinsic_layers(
    s: _Sample, w_raw: irr.WhiteRadiance, w: irr.WhiteRadiance, image: np.ndarray,
    reflectance: np.ndarray, *, denoised: bool,
) -> list[Layer]:
    """sRGB shading, residual, grey shading and illuminant (from the denoised ``W`` if asked,
    with ``image_denoised`` rebuilt from it and the raw ``shading_raw``/``residual_raw``)."""
    from spectrinsic.spectra import xyz_to_linear_srgb

    white = _srgb_white(s)
    used = image
    out: list[Layer] = []
    if denoised:
        raw = s.result.raw[s.ref] if s.ref in s.result.raw else s.result.images[s.ref]
        used = xyz_to_linear_srgb(np.einsum("hwk,ck->hwc", irr.recompose(w, raw), w.to_xyz))
        out.append(_layer("image_denoised", used, _RGB,
                          _UNITS_IMAGE + "; rebuilt as reflectance-weighted denoised white-surface "
                          "radiance (the raw image where no surface)", "image"))
        out += _shading_set(w_raw, _srgb_of(w_raw), white, image, reflectance, space="linear sRGB",
                            names=("shading_raw", "residual_raw"), group="intrinsics")
    out += _shading_set(w, _srgb_of(w), white, used, reflectance, space="linear sRGB",
                        names=("shading", "residual", "illuminant"), group="intrinsics")
    out.append(_layer("shading_grey", irr.luminance_of(w), ("Y",),
                      "luminance Y of the light a perfect white would reflect (render units)",
                      "intrinsics", nonnegative=True))
    out.append(_layer("shading_ratio", shading_ratio(image, reflectance), _RGB,
                      "image / reflectance per channel (thesis Fig. 5.8; ill-conditioned where a "
                      f"reflectance channel is small); 0 where |reflectance| <= {REFLECTANCE_FLOOR:g}",
                      "intrinsics"))
    return out


def _noise(s: _Sample, w: irr.WhiteRadiance) -> tuple[list[Layer], dict[str, Any]]:
    """Relative standard error maps of ``image`` and ``shading`` from the independent batches."""
    from spectrinsic.spectra import xyz_to_linear_srgb

    batches = [b[s.ref] for b in getattr(s.result, "batch_raw", ()) or () if s.ref in b]
    if len(batches) < 2:
        return [], {}
    white = _srgb_white(s)
    images = [xyz_to_linear_srgb(np.einsum("hwk,ck->hwc", np.asarray(b, float), w.to_xyz)) for b in batches]
    shadings = [irr.relative_shading(_srgb_of(w.from_raw(b)), white, w.valid) for b in batches]
    lit = w.valid
    maps = {"image": irr.relative_standard_error(images, lit),
            "shading_raw": irr.relative_standard_error(shadings, lit)}
    layers = [_layer(f"noise_{k}", v, ("Y",),
                     f"relative standard error of the raw {k.removesuffix('_raw')} per pixel, "
                     f"‖se‖₂/‖mean‖₂ over channels, from {len(batches)} independent batches",
                     "noise", nonnegative=True) for k, v in maps.items()]
    figures: dict[str, Any] = {k: irr.noise_figures(v, lit) for k, v in maps.items()}
    figures["batches"] = len(batches)
    return layers, figures


def _light_records(
    s: _Sample, shares: np.ndarray, spaces: Mapping[str, np.ndarray], cameras: Sequence[str]
) -> tuple[LightRecord, ...]:
    from spectrinsic.spectra import get_sensors, get_spectrum, xyz_to_xy

    white = np.ones(s.wl.size)
    cie = get_sensors("cie1931").on(s.wl)
    records = []
    for i, light in enumerate(s.scene.lights):
        spd = get_spectrum(light.spectrum, data_dir=s.data_dir).on(s.wl)
        colour = {k: canonical_responses(white, spd, c, s.wl) for k, c in spaces.items()}
        xy = xyz_to_xy(canonical_responses(white, spd, cie, s.wl))
        records.append(LightRecord(
            index=i, name=light.name, kind=light.kind, spectrum=light.spectrum,
            power=float(light.power), position=tuple(map(float, light.position)),
            direction=tuple(map(float, light.direction)), size=tuple(map(float, light.size)),
            cutoff_deg=float(light.cutoff_deg), xy=(float(xy[0]), float(xy[1])),
            srgb=tuple(float(v) for v in colour["srgb"]),
            camera={_camera_key(c): tuple(float(v) for v in colour[c]) for c in cameras},
            share=float(shares[i]),
        ))
    return tuple(records)


def _per_light_luminance(s: _Sample) -> np.ndarray:
    """``(L, H, W)`` luminance of each light's own render (the reference mode if rendered per
    light, else the per-light share mode)."""
    per_light = tuple(getattr(s.result, "per_light", None) or ())
    lights = s.scene.lights
    if per_light:
        if len(per_light) != len(lights):
            raise DatasetError(f"render has {len(per_light)} per-light images but the scene has "
                               f"{len(lights)} lights")
        return np.stack([np.asarray(pl[s.ref] if s.ref in pl else next(iter(pl.values())),
                                    float)[..., 1] for pl in per_light])
    if len(lights) == 1:
        return np.asarray(s.result.images[s.ref], float)[None, ..., 1]
    raise DatasetError(f"scene {s.scene.name!r} has {len(lights)} lights but the render has no "
                       "per-light images; render with per_light=True")


def _share_layers(s: _Sample, w: irr.WhiteRadiance, mask: np.ndarray) -> tuple[list[Layer], np.ndarray]:
    """Per-pixel share of each light in the light arriving, and each light's share of the
    image's white-surface luminance."""
    y_maps = _per_light_luminance(s)
    share = np.where(w.valid[..., None], irr.share_maps(y_maps), 0.0)
    grey = irr.luminance_of(w)
    weights = share[mask] * grey[mask][:, None]
    totals = weights.sum(axis=0)
    shares = totals / totals.sum() if totals.sum() > 0 else light_shares(y_maps, mask)
    # one light: an (H, W) map, as every single-channel layer is stored
    layer = _layer("light_share", share[..., 0] if share.shape[-1] == 1 else share,
                   tuple(f"L{i}" for i in range(len(s.scene.lights))),
                   "fraction of the light arriving (white-surface luminance) due to each light "
                   "(channel L<i> = meta['lights'][i]); 0 where no surface", "lights",
                   nonnegative=True)
    return [layer], shares


def _camera_layers(
    s: _Sample, cam: str, curves: np.ndarray, coverage: np.ndarray, w: irr.WhiteRadiance,
    *, denoised: bool,
) -> list[Layer]:
    """Camera image from the cube, relative reflectance, and shading/residual/illuminant from
    ``W`` in the camera's RGB (relative to its own white under D65)."""
    from spectrinsic.spectra import get_sensors

    band_set = get_sensors(_cube_sensor_name(s.result), data_dir=s.data_dir)
    weights = cube_to_sensors(band_set.curves, camera_curves(cam, band_set.wavelengths,
                                                             data_dir=s.data_dir), band_set.wavelengths)
    key, slug = _camera_key(cam), "camera-" + camera_slug(cam)
    image = np.asarray(s.result.raw["bands31"], float) @ weights.T
    refl = coverage_weighted(coverage, canonical_responses(s.material_rho, s.d65, curves, s.wl))
    white = canonical_responses(np.ones(s.wl.size), s.d65, curves, s.wl)
    out = [_layer(f"image_camera/{key}", image, _RGB, _UNITS_CAMERA, slug, nonnegative=True),
           _layer(f"reflectance_camera/{key}", refl, _RGB,
                  "dimensionless relative reflectance S_Sen·I^a: camera RGB under D65 "
                  "(perfect white has mean channel 1)", slug, nonnegative=True)]
    used = image
    if denoised:
        used = irr.recompose(w, s.result.raw["bands31"]) @ weights.T
        out.append(_layer(f"image_camera_denoised/{key}", used, _RGB,
                          _UNITS_CAMERA + "; rebuilt from the denoised white-surface radiance", slug))
    names = (f"shading_camera/{key}", f"residual_camera/{key}", f"illuminant_camera/{key}")
    return out + _shading_set(w, w.bands @ weights.T, white, used, refl, names=names, group=slug,
                              space="camera RGB")


def _matrices(s: _Sample, shares: np.ndarray, spaces: Mapping[str, np.ndarray], training: Any) -> dict[str, Any]:
    """The chapter-4 matrices for the scene's effective light and for each light."""
    from spectrinsic.spectra import get_spectrum

    spds = [get_spectrum(light.spectrum, data_dir=s.data_dir).on(s.wl) for light in s.scene.lights]
    illum: dict[str, np.ndarray] = {}
    if spds:
        illum["scene"] = np.einsum("l,lw->w", shares, np.stack(spds))
        illum.update({f"light {i}": spd for i, spd in enumerate(spds)})
    matrices = photometric_matrices(illum, spaces, s.wl, training=training) if illum else {}
    matrices["convention"] = (
        "p = M @ q on column vectors; S_Sen: canonical (D65, sRGB) -> camera under D65; "
        "L_CLig: sensor space under D65 -> under the illuminant; 'scene' is the share-weighted "
        "mix of the lights; least squares over the 1269 Munsell chips, lights at unit luminance"
    )
    return {k: ({_camera_key(c): v for c, v in m.items()} if isinstance(m, dict) else m)
            for k, m in matrices.items()}


def _sample(scene: Scene, result: Any, data_dir: Any) -> _Sample:
    from spectrinsic.spectra import get_spectrum

    wl = _grid()
    rho = (np.stack([get_spectrum(m.spectrum, data_dir=data_dir).on(wl) for m in scene.materials])
           if scene.materials else np.zeros((0, wl.size)))
    return _Sample(scene, result, reference_mode(result), wl, rho,
                   get_spectrum("cie:D65").on(wl), data_dir)


def compute_ground_truth(
    scene: Scene,
    result: RenderRecord,
    *,
    cameras: Sequence[str] = (),
    write_cube: bool = False,
    denoise: bool = False,
    denoise_quality: str = "fast",
    data_dir: Any = None,
    training: np.ndarray | None = None,
) -> GroundTruth:
    """Compute every ground-truth layer of one rendered sample.

    Parameters
    ----------
    scene
        The scene that was rendered (names every material and light spectrum).
    result
        The render (:class:`RenderRecord`).
    cameras
        Sensor-set names (``"camera:Nikon 5100 (NPL)"``); each adds an image integrated from
        the 31-band cube, a relative reflectance, shading, residual and illuminant in that
        camera's RGB.
    write_cube
        Add the raw multispectral cube as layer ``cube``.
    denoise
        Denoise the white-surface radiance with OIDN (:mod:`~spectrinsic.gt_export.denoise`):
        ``shading``, ``residual``, ``illuminant``, ``shading_grey`` and the camera shading
        come from it, ``image_denoised = reflectance ∘ shading + residual`` is rebuilt from it,
        and the raw ``shading_raw``/``residual_raw`` are kept beside ``image``.
    denoise_quality
        OIDN quality, ``"fast"`` (the dataset's, :data:`~spectrinsic.gt_export.denoise.DENOISE_QUALITY`)
        or ``"high"``.
    training
        ``(N, 471)`` reflectances on the 1 nm grid for the matrix fits (default: all Munsell chips).
    """
    from spectrinsic.spectra import absolute_reflectance, get_sensors

    s = _sample(scene, result, data_dir)
    layers = _image_layers(s)
    image = layers[0].data.astype(np.float64)
    coverage, mask = _coverage(s, (image.shape[0], image.shape[1]))
    layers += _geometry_layers(s, mask)
    names = [m.spectrum for m in scene.materials]
    reflectance = coverage_weighted(
        coverage, absolute_reflectance(names, data_dir=data_dir) if names else np.zeros((0, 3)))
    layers.append(_layer("reflectance", reflectance, _RGB,
                         "dimensionless absolute reflectance, linear sRGB under D65 (perfect white = 1); "
                         "box-filtered by pixel coverage, 0 for background", "intrinsics"))
    w_raw = _white_radiance(s, coverage)
    w = w_raw
    if denoise:
        from spectrinsic.gt_export.denoise import denoise_white_radiance

        w = denoise_white_radiance(w_raw, _aov(result, "normals"), quality=denoise_quality)
    layers += _intrinsic_layers(s, w_raw, w, image, reflectance, denoised=denoise)
    noise_layers, noise = _noise(s, w_raw)
    share_layers, shares = _share_layers(s, w, mask)
    layers += noise_layers + share_layers
    spaces: dict[str, np.ndarray] = {"srgb": get_sensors("srgb").on(s.wl)}
    spaces.update({cam: camera_curves(cam, s.wl, data_dir=data_dir) for cam in cameras})
    if cameras and "bands31" not in result.raw:
        raise DatasetError(
            "camera images need the 31-band cube (render mode 'bands31'); render it or pass cameras=()"
        )
    for cam in cameras:
        layers += _camera_layers(s, cam, spaces[cam], coverage, w, denoised=denoise)
    cube_name = _cube_sensor_name(result) if "bands31" in result.raw else None
    if write_cube:
        layers.append(_cube_layer(s, cube_name))
    return GroundTruth(
        layers={layer.name: layer for layer in layers},
        lights=_light_records(s, shares, spaces, cameras),
        materials={str(i): n for i, n in enumerate(names)},
        matrices=_matrices(s, shares, spaces, training),
        reference_mode=s.ref,
        cameras=tuple(cameras),
        cube_sensors=cube_name,
        denoised=tuple(sorted(layer.name for layer in layers if denoise and _from_denoised(layer.name))),
        noise=noise,
        clipping=_clipping(_srgb_of(w) / _srgb_white(s), w.valid & (irr.luminance_of(w) > 0)),
    )


def _clipping(colour: np.ndarray, lit: np.ndarray) -> dict[str, float]:
    """How much out-of-gamut light the clip of the sRGB shading moved into the residual."""
    values = colour[lit]
    if not values.size:
        return {"pixels": 0.0, "mean": 0.0, "max": 0.0}
    clipped = np.linalg.norm(np.clip(values, None, 0.0), axis=-1)
    rel = clipped / np.maximum(np.linalg.norm(values, axis=-1), np.finfo(float).tiny)
    hit = clipped > 0
    return {"pixels": float(hit.mean()), "mean": float(rel[hit].mean()) if hit.any() else 0.0,
            "max": float(rel.max())}


def _from_denoised(name: str) -> bool:
    base = name.split("/", 1)[0]
    return base in ("image_denoised", "shading", "residual", "illuminant", "shading_grey",
                    "light_share", "image_camera_denoised", "shading_camera", "residual_camera",
                    "illuminant_camera")


def _cube_layer(s: _Sample, cube_name: str | None) -> Layer:
    from spectrinsic.spectra import get_sensors

    if cube_name is None:
        raise DatasetError("write_cube needs the 31-band cube (render mode 'bands31')")
    cube = np.asarray(s.result.raw["bands31"], float)
    band_set = get_sensors(cube_name, data_dir=s.data_dir)
    if band_set.n != cube.shape[-1]:
        raise DatasetError(f"cube has {cube.shape[-1]} channels but its sensors {cube_name!r} have {band_set.n}")
    return _layer("cube", cube, band_set.channels,
                  f"band radiance ∫ L B_b dλ (render units) for the bands of {cube_name!r}", "cube",
                  nonnegative=True)


def identities(gt: GroundTruth) -> list[dict[str, str]]:
    """The exact identities the layers satisfy: ``image = reflectance ∘ shading + residual``
    per sensor space (and on the raw layers when denoised); recorded in ``meta.json``."""
    out = []
    denoised = "image_denoised" in gt.layers
    out.append({"image": "image_denoised" if denoised else "image", "reflectance": "reflectance",
                "shading": "shading", "residual": "residual"})
    if denoised:
        out.append({"image": "image", "reflectance": "reflectance", "shading": "shading_raw",
                    "residual": "residual_raw"})
    for cam in gt.cameras:
        key = _camera_key(cam)
        image = f"image_camera_denoised/{key}" if denoised else f"image_camera/{key}"
        out.append({"image": image, "reflectance": f"reflectance_camera/{key}",
                    "shading": f"shading_camera/{key}", "residual": f"residual_camera/{key}"})
    return out
