"""A sample through a camera (``dataset --camera NAME``): raw mosaic, DNG, processed image, noise
variance, and the ground truth carried through the chain's linear stages.

The chain (:mod:`spectrinsic.spectra.camera_chain`) runs on the sample's clean camera image
``image_camera/<camera>`` (the 31-band cube through the camera's curves). Layers, in
``sensor-<camera slug>.exr``:

* ``raw_sensor/<camera>``: the raw Bayer mosaic, DN (black level included; float32 holds every
  integer of a 16-bit ADC exactly), the same numbers as ``sensor-<slug>.dng``;
* ``raw_variance_sensor/<camera>``: the predicted variance of each raw value, DN²;
* ``image_sensor_noisy/<camera>``: the processed linear image (demosaicked, white-balanced,
  colour-matrixed; linear sRGB in camera-image units);
* ``processed_sensor/<camera>``: the tone-mapped 8/16-bit codes (also ``sensor-<slug>.png``);
* ``image_sensor``, ``reflectance_sensor``, ``shading_sensor``, ``residual_sensor`` (and
  ``specular_sensor``) ``/<camera>``: the ground truth in the processed linear space, with
  ``image_sensor = reflectance_sensor ∘ shading_sensor [+ specular_sensor] + residual_sensor``
  recorded among the identities; ``image_sensor`` is the noise-free mean of
  ``image_sensor_noisy``.

The tone curve and quantisation are recorded in ``meta.json["sensor"]`` and never applied to the
ground truth. The noise is seeded by the sample's seed and id: the same sample gives the same raw
bytes, another sample other noise.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...file_writes import write_bytes_file
from ...spectra.camera_chain import ChainResult, carry, run_chain
from ...spectra.camera_isp import camera_to_xyz
from ...spectra.camera_model import CameraModel
from ...spectra.user_spectra import portable_names
from ..formats import png
from ..formats.names import camera_slug
from ..layers import GroundTruth, Layer, camera_curves
from ..layers.gloss import SPECULAR
from ..layers.records import RGB, camera_key, grid, make_layer

__all__ = ["SensorOutput", "sensor_output", "write_sensor_files", "model_from_meta", "noise_seed"]

_LINEAR = "linear sRGB (camera -> XYZ -> sRGB matrix after white balance), camera-image units"


@dataclass(frozen=True)
class SensorOutput:
    """The chain's result for one sample: the ground truth with the sensor layers added, the
    raw frame, and what ``meta.json`` records."""

    ground_truth: GroundTruth
    chain: ChainResult
    model: CameraModel
    slug: str
    identity: dict[str, str]
    meta: dict[str, Any]
    data_dir: Any = None


def noise_seed(seed: int, sample_id: str) -> np.random.SeedSequence:
    """The noise seed of a sample: its render seed and a digest of its id."""
    digest = int.from_bytes(hashlib.sha256(sample_id.encode()).digest()[:8], "little")
    return np.random.SeedSequence([int(seed) & 0xFFFFFFFFFFFFFFFF, digest])


def _illuminant_rgb(gt: GroundTruth, key: str) -> np.ndarray | None:
    """Camera RGB of a perfect white under the scene's share-weighted light, or ``None``."""
    parts = [
        np.asarray(light.camera[key]) * light.share for light in gt.lights if key in light.camera
    ]
    total = np.sum(parts, axis=0) if parts else None
    return total if total is not None and np.all(total > 0) else None


def _layers(
    key: str, slug: str, chain: ChainResult, gt_space: Mapping[str, np.ndarray], bits: int
) -> list[Layer]:
    group = f"sensor-{slug}"
    out = [
        make_layer(
            f"raw_sensor/{key}",
            chain.raw,
            ("DN",),
            "raw DN, Bayer mosaic, black level included",
            group,
            nonnegative=True,
        ),
        make_layer(
            f"raw_variance_sensor/{key}",
            chain.variance,
            ("var",),
            "predicted variance of the raw value, DN²",
            group,
            nonnegative=True,
        ),
        make_layer(
            f"image_sensor_noisy/{key}",
            chain.linear,
            RGB,
            "processed linear image (with sensor noise); " + _LINEAR,
            group,
        ),
        make_layer(
            f"processed_sensor/{key}",
            chain.processed,
            RGB,
            f"{bits}-bit codes after the tone curve (display only)",
            group,
            nonnegative=True,
        ),
    ]
    units = {
        "image": "noise-free processed linear image; " + _LINEAR,
        "reflectance": "reflectance in the processed space: M (camera reflectance / camera white under D65); the white is sRGB (1, 1, 1)",
        "shading": "shading in the processed space: white-balance gains x camera white under D65 x camera shading",
        "residual": "image_sensor - reflectance_sensor * shading_sensor [- specular_sensor]; "
        + _LINEAR,
        SPECULAR: "specular layer through white balance and colour matrix; " + _LINEAR,
    }
    for name, data in gt_space.items():
        out.append(
            make_layer(
                f"{name}_sensor/{key}",
                data,
                RGB,
                units[name],
                group,
                nonnegative=name in ("shading",),
            )
        )
    return out


def sensor_output(
    gt: GroundTruth, model: CameraModel, *, seed: int, sample_id: str, data_dir: Any = None
) -> SensorOutput:
    """Run the camera chain of *model* on *gt*'s camera image and carry its ground truth (the
    known-light balance falls back to grey world for a sample without lights: the recorded
    stages say which ran)."""
    key = camera_key(model.sensitivities)
    needed = f"image_camera/{key}"
    if needed not in gt.layers:
        raise DatasetError(
            f"camera {model.name!r}: the sample has no layer {needed!r} (render mode bands31 with this camera)"
        )
    denoised = f"image_camera_denoised/{key}"
    clean = gt.layers[denoised if denoised in gt.layers else needed].data
    wl = grid()
    curves = camera_curves(model.sensitivities, wl, data_dir=data_dir)
    light = _illuminant_rgb(gt, key)
    used = model
    if light is None and model.white_balance == "illuminant":  # no light to balance for
        used = model.with_options(white_balance="grey-world")
    chain = run_chain(
        used,
        gt.layers[needed].data,
        curves=curves,
        wavelengths=wl,
        seed=noise_seed(seed, sample_id),
        illuminant_rgb=light,
    )
    spec = gt.layers.get(f"specular_camera/{key}")
    space = carry(
        chain,
        image=clean,
        reflectance=gt.layers[f"reflectance_camera/{key}"].data,
        shading=gt.layers[f"shading_camera/{key}"].data,
        specular=None if spec is None else spec.data,
    )
    slug = camera_slug(key)
    layers = dict(gt.layers)
    layers.update(
        {layer.name: layer for layer in _layers(key, slug, chain, space, model.output_bits)}
    )
    identity = {k: f"{k}_sensor/{key}" for k in ("image", "reflectance", "shading", "residual")}
    if spec is not None:
        identity[SPECULAR] = f"{SPECULAR}_sensor/{key}"
    meta = {
        "camera": model.name,
        "model": model.settings(),
        "stages": chain.stages(used),
        "files": {"dng": f"sensor-{slug}.dng", "png": f"sensor-{slug}.png"},
        "noise_seed": {"seed": int(seed), "sample_id": sample_id},
        "carried": "white balance and colour matrix (linear) applied to the ground truth; tone curve and quantisation not",
    }
    return SensorOutput(replace(gt, layers=layers), chain, model, slug, identity, meta, data_dir)


def write_dng(path: Path, out: SensorOutput) -> None:
    """The raw mosaic as an uncompressed DNG (pidng), with CFA layout, black and white levels,
    the colour matrix (XYZ -> camera) and the white balance as shot."""
    from pidng.core import RAW2DNG, DNGTags, Tag
    from pidng.defs import CalibrationIlluminant, CFAPattern, DNGVersion, PhotometricInterpretation

    model, chain = out.model, out.chain
    height, width = chain.raw.shape
    t = DNGTags()
    for tag, value in (
        (Tag.ImageWidth, width),
        (Tag.ImageLength, height),
        (Tag.TileWidth, width),
        (Tag.TileLength, height),
        (Tag.Orientation, 1),
        (Tag.PhotometricInterpretation, PhotometricInterpretation.Color_Filter_Array),
        (Tag.SamplesPerPixel, 1),
        (Tag.BitsPerSample, 16),
        (Tag.CFARepeatPatternDim, [2, 2]),
        (Tag.CFAPattern, getattr(CFAPattern, model.cfa)),
        (Tag.BlackLevel, model.black_level_dn),
        (Tag.WhiteLevel, model.white_level_dn),
        (Tag.ColorMatrix1, _rationals(_xyz_to_camera(out))),
        (Tag.CalibrationIlluminant1, CalibrationIlluminant.D65),
        (Tag.AsShotNeutral, _rationals(1.0 / chain.wb_gains)),
        (Tag.Make, "spectrinsic"),
        (Tag.Model, portable_names(model.name)),  # a sensor CSV by its file name
        (Tag.DNGVersion, DNGVersion.V1_4),
        (Tag.DNGBackwardVersion, DNGVersion.V1_2),
    ):
        t.set(tag, value)
    writer = RAW2DNG()
    writer.options(t, path="", compress=False)
    data = writer.convert(np.ascontiguousarray(chain.raw, dtype=np.uint16))
    write_bytes_file(path, bytes(data))


def _xyz_to_camera(out: SensorOutput) -> np.ndarray:
    """DNG's ColorMatrix1: XYZ (D65) -> camera RGB, ``diag(w65) · camera_to_xyz⁻¹``."""
    wl = grid()
    curves = camera_curves(out.model.sensitivities, wl, data_dir=out.data_dir)
    return out.chain.w65[:, None] * np.linalg.inv(camera_to_xyz(curves, wl))


def _rationals(values: np.ndarray) -> list[list[int]]:
    return [[round(float(v) * 10000), 10000] for v in np.ravel(values)]


def write_sensor_files(folder: str | os.PathLike[str], out: SensorOutput) -> list[str]:
    """Write ``sensor-<slug>.dng`` and ``sensor-<slug>.png`` into *folder*; return their names."""
    folder = Path(folder)
    dng, png_name = out.meta["files"]["dng"], out.meta["files"]["png"]
    write_dng(folder / dng, out)
    if out.model.output_bits == 8:
        png.write_png(folder / png_name, out.chain.processed)
    else:
        png.write_png16(folder / png_name, out.chain.processed)
    return [dng, png_name]


def model_from_meta(meta: Mapping[str, Any]) -> CameraModel | None:
    """The camera model a sample was written with (``meta.json["sensor"]``), or ``None``."""
    record = meta.get("sensor")
    if not record:
        return None
    settings = dict(record["model"])
    settings["sources"] = tuple(
        (str(k), str(v)) for k, v in dict(settings.get("sources", {})).items()
    )
    return CameraModel(**settings)
