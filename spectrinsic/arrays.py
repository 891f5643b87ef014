"""Array aliases with their shapes and units, shared by every package.

All images are linear (never gamma-encoded) unless a name says ``sRGB8``. Besides the arrays,
the callback type of the top layer (:data:`StepProgress`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeAlias

import numpy as np
import numpy.typing as npt

__all__ = [
    "FloatArray",
    "Wavelengths",
    "SpectralValues",
    "SensorCurves",
    "Responses",
    "Matrix3",
    "RGBImage",
    "GreyImage",
    "SpectralImage",
    "Mask",
    "IdMap",
    "StepProgress",
]

FloatArray: TypeAlias = npt.NDArray[np.floating]
#: ``(W,)`` float64, strictly increasing wavelengths in nm.
Wavelengths: TypeAlias = npt.NDArray[np.float64]
#: ``(W,)`` or ``(N, W)`` float64 spectral values on a :data:`Wavelengths` grid
#: (reflectance in [0, 1]; relative spectral power; relative sensitivity).
SpectralValues: TypeAlias = npt.NDArray[np.float64]
#: ``(K, W)`` float64 sensitivities of K sensors on a :data:`Wavelengths` grid.
SensorCurves: TypeAlias = npt.NDArray[np.float64]
#: ``(..., K)`` float64 sensor responses.
Responses: TypeAlias = npt.NDArray[np.float64]
#: ``(3, 3)`` float64 linear map acting on column vectors: ``p = M @ q``.
Matrix3: TypeAlias = npt.NDArray[np.float64]
#: ``(H, W, 3)`` float32 linear RGB image.
RGBImage: TypeAlias = npt.NDArray[np.float32]
#: ``(H, W)`` float32 linear single-channel image.
GreyImage: TypeAlias = npt.NDArray[np.float32]
#: ``(H, W, K)`` float32 linear K-channel (e.g. multispectral) image.
SpectralImage: TypeAlias = npt.NDArray[np.float32]
#: ``(H, W)`` bool, True where a pixel is valid.
Mask: TypeAlias = npt.NDArray[np.bool_]
#: ``(H, W)`` int32 material or object ids, -1 for background.
IdMap: TypeAlias = npt.NDArray[np.int32]
#: Progress callback of a long computation (a study, a benchmark): called once per step with a
#: one-line description of it (e.g. ``"munsell / cie:D65: 3 sensors, 1 bounce(s)"`` or a sample
#: id); the CLI turns it into a progress bar. Not the renderer's pass counter
#: (:data:`spectrinsic.render.passes.Progress`, called with a number of passes).
StepProgress: TypeAlias = Callable[[str], None]
