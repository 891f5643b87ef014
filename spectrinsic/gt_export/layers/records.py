"""Records of ground truth and what every family of layers reads: :class:`Layer`, :class:`LightRecord`,
:class:`GroundTruth`, the render record's accessors and the constants.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...render.result import RenderResult
from ...scenes.model import Scene
from ...spectra import COLORIMETRIC_WAVELENGTHS
from ...spectra.user_spectra import portable_sensor_csv
from ...spectra.working_space import DEFAULT_WORKING_SPACE, WorkingSpace, working_space

# Responses with the light's white at Y = 1; under D65 with sRGB sensors, the canonical p^{s,c}.

__all__ = [
    "REFERENCE_MODES",
    "DEFAULT_CUBE_SENSORS",
    "REFLECTANCE_FLOOR",
    "ERROR_FLOOR",
    "TRAINING_FAMILY",
    "Layer",
    "LightRecord",
    "GroundTruth",
    "grid",
    "aov",
    "reference_mode",
    "cube_sensor_name",
    "camera_key",
    "UNITS_IMAGE",
    "UNITS_CAMERA",
    "RGB",
    "make_layer",
    "SampleInputs",
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
    #: Radius of a sphere light (scene units).
    radius: float
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
    #: Out-of-gamut shading in the working space (clipped into the residual in ``srgb``,
    #: kept in the others): ``pixels``, the fraction of lit pixels with a negative channel;
    #: ``mean``/``max``, the negative part's norm relative to the shading's norm there.
    clipping: dict[str, float] = field(default_factory=dict)
    #: ``Σ|residual| / Σ|image|`` over the mask, per identity, keyed by its image layer
    #: (``image``/``image_denoised``: RGB; ``image_bands``: per band).
    residual_share: dict[str, float] = field(default_factory=dict)
    #: The RGB working space of the RGB layers (``meta.json["working_space"]``).
    working_space: WorkingSpace = field(
        default_factory=lambda: working_space(DEFAULT_WORKING_SPACE)
    )
    #: ``(M, K)`` band albedo of every material in the 31-band cube's bands, the table behind
    #: ``reflectance_bands = coverage @ band_albedos`` (stored once per material, issue 45);
    #: ``None`` without spectral layers.
    band_albedos: np.ndarray | None = field(default=None, repr=False)


def grid() -> np.ndarray:
    return COLORIMETRIC_WAVELENGTHS


def aov(result: RenderResult, name: str) -> np.ndarray | None:
    """The AOV *name* of *result* (``None`` where it was not rendered)."""
    value = result.aovs.get(name)
    return None if value is None else np.asarray(value)


def reference_mode(result: RenderResult) -> str:
    """The render mode whose image is the reference ``image`` (first of :data:`REFERENCE_MODES`;
    for a glossy scene, first of those whose specular part was rendered)."""
    # with glossy materials, the first mode whose specular part was rendered (a diagonal one)
    split = result.specular
    for mode in REFERENCE_MODES:
        if mode in result.images and (not split or mode in split):
            return mode
    if result.images:
        return sorted(result.images)[0]
    raise DatasetError("render result has no images; expected at least one render mode")


def cube_sensor_name(result: RenderResult) -> str:
    sensors = result.meta.get("sensors")
    if isinstance(sensors, Mapping) and isinstance(sensors.get("bands31"), str):
        return sensors["bands31"]
    log.info("render meta names no sensors for 'bands31'; assuming %s", DEFAULT_CUBE_SENSORS)
    return DEFAULT_CUBE_SENSORS


def camera_key(name: str) -> str:
    """The key of camera *name*'s layers: ``camera:X`` -> ``X``; a sensor CSV by its portable
    name (``csv:/abs/cam.csv`` -> ``csv:cam.csv``: no written name holds a builder's path)."""
    if name.startswith("camera:"):
        return name.split(":", 1)[1]
    return portable_sensor_csv(name) if name[:4].lower() == "csv:" else name


UNITS_IMAGE = (
    "relative radiance (render units), linear RGB of the working space "
    "(meta.json working_space), from CIE XYZ"
)


UNITS_CAMERA = (
    "relative radiance (render units) in the camera's raw linear RGB; curves scaled so the "
    "perfect white under D65 has mean channel 1"
)


RGB = ("R", "G", "B")


def make_layer(
    name: str,
    data: np.ndarray,
    channels: Sequence[str],
    units: str,
    group: str,
    nonnegative: bool = False,
) -> Layer:
    return Layer(
        name, np.asarray(data, dtype=np.float32), tuple(channels), units, group, nonnegative
    )


@dataclass(frozen=True, eq=False)
class SampleInputs:
    """What every family of layers reads: the scene, the render and the spectra on the 1 nm grid."""

    scene: Scene
    result: RenderResult
    ref: str
    wl: np.ndarray
    material_rho: np.ndarray
    d65: np.ndarray
    data_dir: Any
    #: The RGB working space of the layers (:mod:`spectrinsic.spectra.working_space`).
    space: WorkingSpace = field(default_factory=lambda: working_space(DEFAULT_WORKING_SPACE))
