"""Array aliases with their shapes and units, shared by every package.

All images are linear (never gamma-encoded) unless a name says ``sRGB8``.
"""

from __future__ import annotations

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
