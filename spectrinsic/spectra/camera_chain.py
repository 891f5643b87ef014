"""The whole camera chain: a clean camera image -> raw mosaic -> processed image, and the same
linear stages applied to the ground truth.

Stages, each recorded in :class:`ChainResult`:

1. exposure: electrons per unit of the camera image (fixed, or metered as a camera meters: the
   median luminance of the lit pixels brought to ``exposure_target`` of the full well, middle
   grey by default, so highlights may saturate; :func:`exposure_scale`);
2. mosaic (Bayer ``cfa``) and sensor noise (:func:`spectrinsic.spectra.camera_noise.capture`),
   seeded per sample: the raw frame in DN and its predicted variance;
3. black level removed and DN brought back to camera units (``× gain / electrons per unit``);
4. demosaic (colour-demosaicing); white balance ``D``; colour matrix ``M`` (camera → XYZ →
   linear sRGB, fitted from the curves): the *processed linear* image, ``M D rgb``;
5. tone curve and quantisation to 8/16 bit: the processed image (display only).

Stages 3–4 are linear, so the ground truth goes through them too (:func:`carry`): with
``w65`` the camera's white under D65,

* ``image' = M D image``, ``specular' = M D specular``;
* ``reflectance' = M (reflectance / w65)`` (a perfect white becomes the sRGB white);
* ``shading' = D (w65 ∘ shading)`` (after the known-illuminant balance, the light's colour is
  removed: a lit white surface is grey);
* ``residual' = image' − reflectance' ∘ shading' [− specular']``, so the identity holds in the
  processed linear space; it holds the noise-free residual carried through ``M D`` plus the part
  of ``M`` that does not commute with a coloured shading (zero where ``shading'`` is grey).

Stage 5 is not linear: it is recorded, never applied to ground-truth layers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import camera_isp as isp
from .camera_model import CameraModel
from .camera_noise import capture
from .colorimetry import white_normalised_responses
from .registry import get_spectrum

__all__ = [
    "ChainResult",
    "EXPOSURE_PERCENTILE",
    "exposure_scale",
    "run_chain",
    "carry",
    "camera_white_d65",
]

#: Percentile of the lit pixels' luminance that the automatic exposure places on the target: the
#: median, as a camera's centre-weighted or evaluative meter aims the scene's typical
#: luminance at middle grey (ISO 2720's reflected-light calibration), whatever its highlights.
EXPOSURE_PERCENTILE = 50.0


@dataclass(frozen=True)
class ChainResult:
    """One frame through the chain.

    Attributes
    ----------
    raw
        ``(H, W) uint16`` raw mosaic, DN (black level included).
    variance
        ``(H, W) float32`` predicted variance of ``raw``, DN².
    linear
        ``(H, W, 3) float32`` processed linear image (demosaicked, balanced, colour-matrixed),
        camera-image units: its noise-free mean is ``M D image``.
    processed
        ``(H, W, 3)`` uint8 or uint16 codes after the tone curve.
    electrons_per_unit
        Exposure: electrons per unit of the camera image.
    wb_gains
        ``(3,)`` white-balance gains ``D``.
    matrix
        ``(3, 3)`` colour matrix ``M`` (identity when off).
    w65
        ``(3,)`` the camera's white under D65 (mean channel 1 for :func:`camera_curves` curves).
    display_gain
        Factor on the processed linear image before the tone curve (the full well maps to 1).
    """

    raw: np.ndarray
    variance: np.ndarray
    linear: np.ndarray
    processed: np.ndarray
    electrons_per_unit: float
    wb_gains: np.ndarray
    matrix: np.ndarray
    w65: np.ndarray
    display_gain: float

    def stages(self, model: CameraModel) -> dict[str, object]:
        """Plain data of every stage, for ``meta.json``."""
        return {
            "exposure": {"electrons_per_unit": self.electrons_per_unit},
            "mosaic": {"cfa": model.cfa},
            "noise": "photon-transfer model (spectrinsic.spectra.camera_noise), seeded per sample",
            "adc": {
                "bits": model.adc_bits,
                "black_level_dn": model.black_level_dn,
                "white_level_dn": model.white_level_dn,
                "gain_e_per_dn": model.gain,
            },
            "demosaic": model.demosaic,
            "white_balance": {"method": model.white_balance, "gains": self.wb_gains.tolist()},
            "colour_matrix": {
                "applied": model.colour_matrix,
                "camera_to_linear_srgb": self.matrix.tolist(),
                "fit": "colour-science matrix_colour_correction (Cheung 2004, 3 terms), "
                "24 ColorChecker patches under D65",
            },
            "tone_curve": {
                "curve": model.tone_curve,
                "display_gain": self.display_gain,
                "applied_to_ground_truth": False,
            },
            "output_bits": model.output_bits,
        }


def camera_white_d65(curves: np.ndarray, wavelengths: np.ndarray) -> np.ndarray:
    """``(3,)`` camera RGB of a perfect white under D65 (white luminance Y = 1)."""
    d65 = get_spectrum("cie:D65").on(wavelengths)
    return white_normalised_responses(np.ones(wavelengths.size), d65, curves, wavelengths)


def exposure_scale(model: CameraModel, image: np.ndarray) -> float:
    """Electrons per unit of *image*: fixed, or metered: the :data:`EXPOSURE_PERCENTILE` of the
    luminance of the lit pixels (the mean over channels, the camera's curves being scaled so
    the perfect white under D65 has mean channel 1) at ``exposure_target`` of the full well.
    A scene of saturated lights around one bright patch is metered on its typical pixel, not on
    the patch, which saturates as it would in a photograph. 1 e⁻ per unit for a black image."""
    if model.electrons_per_unit is not None:
        return float(model.electrons_per_unit)
    luminance = np.asarray(image, np.float64).mean(axis=-1).ravel()
    lit = luminance[luminance > 0]
    level = float(np.percentile(lit, EXPOSURE_PERCENTILE)) if lit.size else 0.0
    return model.exposure_target * model.full_well_e / level if level > 0 else 1.0


def run_chain(
    model: CameraModel,
    image: np.ndarray,
    *,
    curves: np.ndarray,
    wavelengths: np.ndarray,
    seed: int | np.random.SeedSequence,
    illuminant_rgb: np.ndarray | None = None,
) -> ChainResult:
    """Run *image* (``(H, W, 3)`` clean camera RGB, ≥ 0, the camera's *curves* on
    *wavelengths*) through the chain of *model*; *illuminant_rgb* is the camera RGB of the
    known light (for ``white_balance="illuminant"``); *seed* seeds the noise."""
    image = np.maximum(np.asarray(image, np.float64), 0.0)
    scale = exposure_scale(model, image)
    frame = capture(model, isp.mosaic(image, model.cfa) * scale, seed=seed)
    cfa = (frame.raw.astype(np.float64) - model.black_level_dn) * (model.gain / scale)
    rgb = isp.demosaic(cfa, model.cfa, model.demosaic)
    if model.white_balance == "illuminant" and illuminant_rgb is None:
        raise ValueError("white balance 'illuminant': expected the light's camera RGB")
    gains = isp.white_balance_gains(model.white_balance, rgb, illuminant_rgb)
    matrix = isp.processing_matrix(model, curves, wavelengths)
    linear = np.einsum("kj,hwj->hwk", matrix * gains[None, :], rgb)
    display_gain = scale / model.full_well_e
    encoded = isp.tone_curve(linear * display_gain, model.tone_curve)
    return ChainResult(
        raw=frame.raw,
        variance=frame.variance,
        linear=linear.astype(np.float32),
        processed=isp.quantise(encoded, model.output_bits),
        electrons_per_unit=scale,
        wb_gains=gains,
        matrix=matrix,
        w65=camera_white_d65(curves, wavelengths),
        display_gain=display_gain,
    )


def carry(
    chain: ChainResult,
    *,
    image: np.ndarray,
    reflectance: np.ndarray,
    shading: np.ndarray,
    specular: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """The ground truth through the chain's linear stages (module doc): ``image``,
    ``reflectance``, ``shading``, ``residual`` and, if given, ``specular``, each ``(H, W, 3)``
    float32 in the processed linear space; ``image = reflectance ∘ shading [+ specular] +
    residual`` holds to float rounding."""
    md = chain.matrix * chain.wb_gains[None, :]

    def apply(m: np.ndarray, x: np.ndarray) -> np.ndarray:
        return np.einsum("kj,hwj->hwk", m, np.asarray(x, np.float64))

    out = {
        "image": apply(md, image),
        "reflectance": apply(chain.matrix, np.asarray(reflectance, np.float64) / chain.w65),
        "shading": np.asarray(shading, np.float64) * (chain.wb_gains * chain.w65),
    }
    if specular is not None:
        out["specular"] = apply(md, specular)
    out = {k: v.astype(np.float32) for k, v in out.items()}
    residual = out["image"] - out["reflectance"] * out["shading"]
    if specular is not None:
        residual = residual - out["specular"]
    out["residual"] = residual
    return out
