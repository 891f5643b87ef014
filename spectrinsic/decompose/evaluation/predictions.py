"""Scoring anyone's method: estimates read from files in a documented layout.

Layout of a predictions folder ``DIR`` (what ``spectrinsic evaluate --predictions DIR`` reads)::

    DIR/<sample_id>/reflectance.exr      and/or   DIR/<sample_id>/shading.exr
    DIR/<sample_id>/reflectance.png      and/or   DIR/<sample_id>/shading.png
    DIR/<sample_id>/<scenario>/...       optional: the camera scenarios (e.g. SC4_nikon-5100-npl)

* ``<sample_id>`` is the sample folder's name in the dataset. The input to decompose is the
  sample's ``image_denoised`` layer when it has one, else ``image`` (linear sRGB, render units;
  :data:`spectrinsic.decompose.evaluation.evaluate.INPUT_LAYERS`); for a camera scenario, the camera image
  after that scenario's correction (``estimates/<method>/<scenario>/`` of a bundled run shows it).
* **EXR**: linear values at any scale (every metric fits a scale), float16 or float32; the layer
  named ``reflectance`` / ``shading``, or the file's only layer. Reflectance is ``(H, W, 3)``;
  shading is ``(H, W, 3)`` or one channel (grey).
* **PNG**: 16 bits per channel (8-bit files are refused), RGB or grey, ``value = code / 65535``
  with ``encoding="linear"`` (default; any scale) or sRGB-encoded codes
  (``encoding="srgb"``, IEC 61966-2-1, decoded to linear before scoring).
* When only one of the two layers is given, the other is derived so that
  ``image = reflectance * shading`` per channel (thesis Eq. 3.1): ``shading = image /
  reflectance`` or ``reflectance = image / shading`` (grey shading applies to all channels).
* Optional ``DIR/<sample_id>/specular.exr`` (or ``.png``): a predicted specular image
  (``(H, W, 3)``, linear sRGB at the image's scale), scored against a glossy sample's
  ``specular`` layer (:mod:`spectrinsic.decompose.evaluation.targets`). On the full-image target it is
  subtracted from the image before a missing layer is derived (``image − specular =
  reflectance * shading``); on the diffuse target the image is diffuse already.
* A sample without any file is an error; a camera scenario without files is not scored.

If both an EXR and a PNG are present, the EXR is used. :func:`write_predictions` writes this
layout (the one writer of it), so a method's arrays reach ``evaluate`` without hand-made files.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Literal

import numpy as np

from ...errors import DatasetError, validate_choice
from ...gt_export.formats.exr import exr_size, read_exr, write_exr
from ...gt_export.formats.png import PNG16_MAX, png_size, read_png16, write_png16
from ...path_kinds import folder_problem
from ...spectra.colorimetry import decode_srgb, encode_srgb
from ..decomposition import Decomposition, finish

__all__ = [
    "PNG_ENCODINGS",
    "PREDICTION_FORMATS",
    "Predictions",
    "PredictionFiles",
    "read_layer",
    "write_predictions",
]

logger = logging.getLogger(__name__)

#: How 16-bit PNG codes map to linear values.
PNG_ENCODINGS = ("linear", "srgb")
#: File formats of :func:`write_predictions`: float32 OpenEXR or 16-bit PNG.
PREDICTION_FORMATS = ("exr", "png")


def _from_exr(path: Path, layer: str) -> np.ndarray:
    arrays = read_exr(path)
    if layer in arrays:
        return arrays[layer]
    if len(arrays) == 1:
        return next(iter(arrays.values()))
    raise DatasetError(
        f"{path}: expected a layer {layer!r} or a single layer; it holds {sorted(arrays)}"
    )


def _from_png(path: Path, encoding: str) -> np.ndarray:
    values = read_png16(path).astype(np.float64) / PNG16_MAX
    return decode_srgb(values) if encoding == "srgb" else values


#: Most channels a prediction file may hold (a layer is 1 or 3; a few extra are tolerated).
MAX_CHANNELS = 8


def _check_header_size(path: Path, layer: str, shape: tuple[int, int]) -> None:
    """Refuse a file whose header declares another image size than the sample's, before its
    pixels are decoded: memory then stays bounded by the dataset's own image size."""

    if path.suffix == ".exr":
        height, width, channels = exr_size(path)
    else:
        (height, width), channels = png_size(path), 0
    if (height, width) != tuple(shape):
        raise DatasetError(
            f"{path}: expected a {layer} image of shape {(*shape, 3)}; its header "
            f"declares {width}x{height} pixels (refused before decoding)"
        )
    if channels > MAX_CHANNELS:
        raise DatasetError(
            f"{path}: its header declares {channels} channels; expected a {layer} "
            f"image of at most {MAX_CHANNELS}"
        )


def read_layer(
    folder: Path, layer: str, shape: tuple[int, int], *, encoding: str
) -> np.ndarray | None:
    """Read ``folder/<layer>.exr`` (else ``.png``) as float64 ``(H, W, 3)``; None when absent.

    A grey shading (one channel) is repeated to 3 channels. Raises :class:`DatasetError` for a
    wrong image size, a grey reflectance, or NaN/Inf values.
    """
    exr, png = folder / f"{layer}.exr", folder / f"{layer}.png"
    if exr.is_file():
        _check_header_size(exr, layer, shape)
        values, path = _from_exr(exr, layer), exr
    elif png.is_file():
        _check_header_size(png, layer, shape)
        values, path = _from_png(png, encoding), png
    else:
        return None
    values = np.asarray(values, dtype=np.float64)
    if values.ndim == 3 and values.shape[2] == 1:
        values = values[:, :, 0]
    if values.ndim == 2 and layer == "shading":
        values = np.repeat(values[:, :, None], 3, axis=2)
    if values.shape != (*shape, 3):
        raise DatasetError(
            f"{path}: expected a {layer} image of shape {(*shape, 3)}"
            f"{' or ' + str(shape) if layer == 'shading' else ''}; got {values.shape}"
        )
    if not np.all(np.isfinite(values)):
        raise DatasetError(f"{path}: {layer} contains NaN or Inf values")
    return values


def _divide(image: np.ndarray, by: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(by > 0.0, image / np.where(by > 0.0, by, 1.0), 0.0)


@dataclass(frozen=True)
class Predictions:
    """A method whose estimates are files (module docstring for the layout).

    Attributes
    ----------
    root
        The predictions folder.
    encoding
        Encoding of 16-bit PNG files: ``"linear"`` or ``"srgb"``.
    name
        The method's name in the tables.
    """

    root: Path
    encoding: Literal["linear", "srgb"] = "linear"
    name: str = "predictions"

    def __post_init__(self) -> None:
        validate_choice(self.encoding, PNG_ENCODINGS, "PNG encoding", error=DatasetError)
        if (problem := folder_problem(self.root)) is not None:
            raise DatasetError(f"predictions folder {str(self.root)!r} {problem}")

    def folder(self, sample_id: str, scenario: str) -> Path:
        """Where the files of one sample and scenario (``"srgb"``: the sample folder) lie."""
        base = Path(self.root) / sample_id
        return base if scenario == "srgb" else base / scenario

    def load(
        self,
        sample_id: str,
        scenario: str,
        image: np.ndarray,
        mask: np.ndarray,
        *,
        subtract_specular: bool = True,
    ) -> Decomposition | None:
        """The estimate of one sample and scenario, completed from *image* (module docstring).

        *subtract_specular*: a predicted specular is part of *image* (the full-image target)
        and is removed from it before a missing layer is derived.
        Returns None for a camera scenario without files; raises :class:`DatasetError` for a
        sample (``scenario="srgb"``) without any.
        """
        folder = self.folder(sample_id, scenario)
        shape = (int(image.shape[0]), int(image.shape[1]))
        refl = read_layer(folder, "reflectance", shape, encoding=self.encoding)
        shad = read_layer(folder, "shading", shape, encoding=self.encoding)
        spec = read_layer(folder, "specular", shape, encoding=self.encoding)
        if refl is None and shad is None:
            if scenario == "srgb":
                raise DatasetError(
                    f"predictions {self.name!r}: no reflectance or shading (.exr or 16-bit .png) "
                    f"in {str(folder)!r}; to score only the samples you predicted, pass "
                    "--samples with their ids or globs (e.g. --samples 'obj-*')"
                )
            logger.info("predictions %s: no files for %s / %s", self.name, sample_id, scenario)
            return None
        img = np.asarray(image, dtype=np.float64)
        img = np.clip(img - spec if spec is not None and subtract_specular else img, 0.0, None)
        if refl is None:
            assert shad is not None  # narrowed by the check above
            refl = _divide(img, shad)
        m = mask[:, :, None]
        spec32 = None if spec is None else np.where(m, spec, 0.0).astype(np.float32)
        if shad is None:
            return replace(finish(img, refl, mask, {"source": str(folder)}), specular=spec32)
        return Decomposition(
            np.where(m, refl, 0.0).astype(np.float32),
            np.where(m, shad, 0.0).astype(np.float32),
            {"source": str(folder)},
            spec32,
        )


@dataclass(frozen=True)
class PredictionFiles:
    """What :func:`write_predictions` wrote.

    Attributes
    ----------
    folder
        ``root/<sample_id>[/<scenario>]``.
    files
        Layer name -> file written.
    scales
        Layer name -> the factor the values were divided by before encoding (1 for EXR and
        for PNG layers within [0, 1]); every metric fits a scale, so it changes no score.
    """

    folder: Path
    files: Mapping[str, Path] = field(default_factory=dict)
    scales: Mapping[str, float] = field(default_factory=dict)


def _plain_name(value: str, what: str) -> str:
    """*value* if it is one folder name (no separator, not ``.``/``..``), else a DatasetError."""
    if (
        not isinstance(value, str)
        or not value
        or value in (".", "..")
        or "/" in value
        or "\\" in value
        or os.sep in value
    ):
        raise DatasetError(
            f"write_predictions: {what} {value!r}; expected one folder name, "
            "e.g. 'room-living__v1__white'"
        )
    return value


def _layer_values(layer: str, values: np.ndarray) -> np.ndarray:
    """*values* as float64 ``(H, W, 3)``, or ``(H, W)`` for a grey shading; checked."""
    arr = np.asarray(values, dtype=np.float64)
    if arr.ndim == 3 and arr.shape[2] == 1 and layer == "shading":
        arr = arr[:, :, 0]
    if not (arr.ndim == 3 and arr.shape[2] == 3) and not (arr.ndim == 2 and layer == "shading"):
        raise DatasetError(
            f"write_predictions: {layer} of shape {arr.shape}; expected (H, W, 3)"
            + (" or (H, W)" if layer == "shading" else "")
        )
    if not np.all(np.isfinite(arr)):
        raise DatasetError(f"write_predictions: {layer} contains NaN or Inf values")
    return arr


def _png_codes(values: np.ndarray, encoding: str) -> tuple[np.ndarray, float]:
    """16-bit codes of linear *values* (negatives clipped to 0) and the scale divided out:
    the layer's maximum when it exceeds 1, so the codes use their whole range."""

    values = np.clip(values, 0.0, None)
    scale = max(1.0, float(values.max(initial=0.0)))
    unit = values / scale
    if encoding == "srgb":
        unit = encode_srgb(unit)
    return np.rint(unit * PNG16_MAX).astype(np.uint16), scale


def write_predictions(
    root: str | os.PathLike[str],
    sample_id: str,
    *,
    reflectance: np.ndarray | None = None,
    shading: np.ndarray | None = None,
    specular: np.ndarray | None = None,
    fmt: Literal["exr", "png"] = "exr",
    encoding: Literal["linear", "srgb"] = "linear",
    scenario: str | None = None,
    overwrite: bool = False,
) -> PredictionFiles:
    """Write one sample's estimates in the layout ``evaluate --predictions`` reads.

    Parameters
    ----------
    root
        The predictions folder (created if needed).
    sample_id
        The sample folder's name in the dataset.
    reflectance, shading
        Linear estimates at any scale: reflectance ``(H, W, 3)``, shading ``(H, W, 3)`` or
        grey ``(H, W)``; at least one. The missing one is derived by the reader from
        ``image = reflectance * shading`` (thesis Eq. 3.1).
    specular
        Optional linear ``(H, W, 3)`` specular estimate at the image's scale (scored against a
        glossy sample's ``specular`` layer; module docstring).
    fmt
        ``"exr"``: float32 OpenEXR, the values as given. ``"png"``: 16-bit PNG,
        ``code = round(65535 * value / scale)`` with ``scale = max(1, layer maximum)`` and
        negatives clipped to 0, so 1/65535 of the range is the quantisation step.
    encoding
        PNG codes linear (``evaluate --png-encoding linear``, the default) or sRGB-encoded
        (IEC 61966-2-1; ``--png-encoding srgb``). Ignored for EXR.
    scenario
        A camera scenario (e.g. ``"SC4_nikon-5100-npl"``): written to
        ``root/<sample_id>/<scenario>/``.
    overwrite
        Replace files already there. Without it an existing file is an error: this writer
        never replaces a file it may not have written.

    Returns
    -------
    PredictionFiles
        The folder, the files and the scale divided out of each layer.

    Raises
    ------
    DatasetError
        No layer given, a bad shape, NaN/Inf, a bad name, format or encoding, an existing file
        (without *overwrite*), or a PNG that an EXR of the same layer would hide from the
        reader.
    """
    validate_choice(fmt, PREDICTION_FORMATS, "predictions format", error=DatasetError)
    validate_choice(encoding, PNG_ENCODINGS, "PNG encoding", error=DatasetError)
    given = (("reflectance", reflectance), ("shading", shading), ("specular", specular))
    layers = {k: v for k, v in given if v is not None}
    if set(layers) == {"specular"}:
        raise DatasetError("write_predictions: give reflectance, shading or both with specular")
    if not layers:
        raise DatasetError("write_predictions: give reflectance, shading or both")
    folder = Path(root) / _plain_name(sample_id, "sample id")
    if scenario is not None:
        folder = folder / _plain_name(scenario, "scenario")
    arrays = {k: _layer_values(k, v) for k, v in layers.items()}
    for name in arrays:
        target, hider = folder / f"{name}.{fmt}", folder / f"{name}.exr"
        if target.exists() and not overwrite:
            raise DatasetError(f"{target} exists; pass overwrite=True to replace it")
        if fmt == "png" and hider.exists():
            raise DatasetError(
                f"{hider} exists and the reader prefers it to {target.name}; remove it or write EXR"
            )
    folder.mkdir(parents=True, exist_ok=True)
    return PredictionFiles(folder, *_write_layers(folder, arrays, fmt, encoding))


def _write_layers(
    folder: Path, arrays: Mapping[str, np.ndarray], fmt: str, encoding: str
) -> tuple[dict[str, Path], dict[str, float]]:
    files, scales = {}, {}
    for name, arr in arrays.items():
        if fmt == "exr":
            files[name] = write_exr(folder / f"{name}.exr", {name: arr.astype(np.float32)})
            scales[name] = 1.0
        else:
            codes, scales[name] = _png_codes(arr, encoding)
            files[name] = write_png16(folder / f"{name}.png", codes)
    return files, scales
