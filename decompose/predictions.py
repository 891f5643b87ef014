"""Scoring anyone's method: estimates read from files in a documented layout.

Layout of a predictions folder ``DIR`` (what ``spectrinsic evaluate --predictions DIR`` reads)::

    DIR/<sample_id>/reflectance.exr      and/or   DIR/<sample_id>/shading.exr
    DIR/<sample_id>/reflectance.png      and/or   DIR/<sample_id>/shading.png
    DIR/<sample_id>/<scenario>/...       optional: the camera scenarios (e.g. SC4_nikon-5100-npl)

* ``<sample_id>`` is the sample folder's name in the dataset. The input to decompose is the
  sample's ``image_denoised`` layer when it has one, else ``image`` (linear sRGB, render units;
  :data:`spectrinsic.decompose.evaluate.INPUT_LAYERS`); for a camera scenario, the camera image
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
* A sample without any file is an error; a camera scenario without files is not scored.

If both an EXR and a PNG are present, the EXR is used.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from spectrinsic.decompose.decomposition import Decomposition, finish
from spectrinsic.errors import DatasetError, validate_choice
from spectrinsic.gt_export.exr import read_exr
from spectrinsic.gt_export.png import PNG16_MAX, read_png16
from spectrinsic.spectra.colorimetry import decode_srgb

__all__ = ["PNG_ENCODINGS", "Predictions", "read_layer"]

logger = logging.getLogger(__name__)

#: How 16-bit PNG codes map to linear values.
PNG_ENCODINGS = ("linear", "srgb")


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
    from spectrinsic.gt_export.exr import exr_size
    from spectrinsic.gt_export.png import png_size

    if path.suffix == ".exr":
        height, width, channels = exr_size(path)
    else:
        (height, width), channels = png_size(path), 0
    if (height, width) != tuple(shape):
        raise DatasetError(f"{path}: expected a {layer} image of shape {(*shape, 3)}; its header "
                           f"declares {width}x{height} pixels (refused before decoding)")
    if channels > MAX_CHANNELS:
        raise DatasetError(f"{path}: its header declares {channels} channels; expected a {layer} "
                           f"image of at most {MAX_CHANNELS}")


def read_layer(folder: Path, layer: str, shape: tuple[int, int], *, encoding: str) -> np.ndarray | None:
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
        if not Path(self.root).is_dir():
            raise DatasetError(f"predictions folder {str(self.root)!r} does not exist")

    def folder(self, sample_id: str, scenario: str) -> Path:
        """Where the files of one sample and scenario (``"srgb"``: the sample folder) lie."""
        base = Path(self.root) / sample_id
        return base if scenario == "srgb" else base / scenario

    def load(
        self, sample_id: str, scenario: str, image: np.ndarray, mask: np.ndarray
    ) -> Decomposition | None:
        """The estimate of one sample and scenario, completed from *image* (module docstring).

        Returns None for a camera scenario without files; raises :class:`DatasetError` for a
        sample (``scenario="srgb"``) without any.
        """
        folder = self.folder(sample_id, scenario)
        shape = (int(image.shape[0]), int(image.shape[1]))
        refl = read_layer(folder, "reflectance", shape, encoding=self.encoding)
        shad = read_layer(folder, "shading", shape, encoding=self.encoding)
        if refl is None and shad is None:
            if scenario == "srgb":
                raise DatasetError(
                    f"predictions {self.name!r}: no reflectance or shading (.exr or 16-bit .png) "
                    f"in {str(folder)!r}"
                )
            logger.info("predictions %s: no files for %s / %s", self.name, sample_id, scenario)
            return None
        img = np.clip(np.asarray(image, dtype=np.float64), 0.0, None)
        if refl is None:
            assert shad is not None  # narrowed by the check above
            refl = _divide(img, shad)
        if shad is None:
            return finish(img, refl, mask, {"source": str(folder)})
        m = mask[:, :, None]
        return Decomposition(np.where(m, refl, 0.0).astype(np.float32),
                             np.where(m, shad, 0.0).astype(np.float32), {"source": str(folder)})
