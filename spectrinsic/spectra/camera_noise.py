"""Sensor noise: mean electrons per pixel -> raw DN, and the per-pixel variance the model predicts.

The photon-transfer model of :mod:`spectrinsic.spectra.camera_model` (EMVA 1288):

* fixed pattern, the same every frame (seeded by the camera's ``fixed_pattern_seed``): a pixel's
  gain ``1 + prnu · n₁`` and a dark offset ``dsnu_e · n₂`` electrons;
* shot noise: ``e ~ Poisson(q · (1 + prnu · n₁) + dark_current · t + dsnu · n₂)``, clipped at the
  full well;
* read noise: Gaussian of ``read_noise_e`` (or ELD's Tukey-lambda tail), plus a per-row offset
  of ``row_noise_e`` electrons;
* ADC: ``DN = round(e / gain + black)``, clipped to ``[0, 2**bits - 1]``.

Every random draw comes from one :class:`numpy.random.Generator` seeded per sample, so the same
seed gives the same raw bytes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .camera_model import CameraModel

__all__ = ["RawCapture", "fixed_pattern", "capture", "noise_variance_dn", "tail_variance"]

#: Variance of rounding to the nearest integer, DN² (a uniform error on [-1/2, 1/2]).
QUANTISATION_VARIANCE = 1.0 / 12.0


@dataclass(frozen=True)
class RawCapture:
    """One raw frame.

    Attributes
    ----------
    raw
        ``(H, W) uint16`` DN, black level included.
    variance
        ``(H, W) float32`` predicted variance of ``raw`` around its mean, DN².
    mean_electrons
        ``(H, W) float64`` expected electrons before clipping (fixed pattern and dark current
        included).
    """

    raw: np.ndarray
    variance: np.ndarray
    mean_electrons: np.ndarray


def fixed_pattern(model: CameraModel, shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """``(gain map, dark offset map in electrons)`` of one camera body: the same for every frame
    of the same *shape* (seeded by ``model.fixed_pattern_seed``)."""
    rng = np.random.default_rng([model.fixed_pattern_seed, shape[0], shape[1]])
    gain = 1.0 + model.prnu * rng.standard_normal(shape)
    offset = model.dsnu_e * rng.standard_normal(shape)
    return np.maximum(gain, 0.0), offset


def tail_variance(model: CameraModel) -> float:
    """Variance of the read noise in electrons² (Gaussian, or ELD's Tukey-lambda tail)."""
    if model.tail_lambda is None:
        return model.read_noise_e**2
    from scipy import stats

    return float(stats.tukeylambda(model.tail_lambda).var()) * model.tail_scale_e**2


def _read_noise(model: CameraModel, shape: tuple[int, int], rng: np.random.Generator) -> np.ndarray:
    if model.tail_lambda is None:
        noise = model.read_noise_e * rng.standard_normal(shape)
    else:
        from scipy import stats

        noise = model.tail_scale_e * stats.tukeylambda(model.tail_lambda).rvs(
            size=shape, random_state=rng
        )
    if model.row_noise_e > 0:
        noise = noise + model.row_noise_e * rng.standard_normal((shape[0], 1))
    return np.asarray(noise)


def capture(
    model: CameraModel, electrons: np.ndarray, *, seed: int | np.random.SeedSequence
) -> RawCapture:
    """Raw DN of one frame from the mean photo-electrons per pixel.

    Parameters
    ----------
    electrons
        ``(H, W)`` expected photo-electrons per pixel (signal only, ≥ 0), e.g. the mosaicked
        camera image times the exposure.
    seed
        The frame's seed: the same seed gives the same raw values.
    """
    q = np.asarray(electrons, dtype=np.float64)
    if q.ndim != 2:
        raise ValueError(f"electrons: expected an (H, W) array, got shape {q.shape}")
    rng = np.random.default_rng(seed)
    shape = (q.shape[0], q.shape[1])
    gain_map, offset = fixed_pattern(model, shape)
    dark = model.dark_current_e_per_s * model.exposure_time_s
    mean = np.maximum(q * gain_map + dark + offset, 0.0)
    signal = np.minimum(rng.poisson(mean).astype(np.float64), model.full_well_e)
    signal += _read_noise(model, shape, rng)
    dn = np.rint(signal / model.gain + model.black_level_dn)
    raw = np.clip(dn, 0, 2**model.adc_bits - 1).astype(np.uint16)
    return RawCapture(raw, noise_variance_dn(model, mean), mean)


def noise_variance_dn(model: CameraModel, mean_electrons: np.ndarray) -> np.ndarray:
    """Predicted per-pixel variance of the raw value, DN²: shot noise ``min(e, full well) / g²``
    (none once saturated), read and row noise ``(σ_r² + σ_row²) / g²`` and rounding ``1/12``."""
    e = np.asarray(mean_electrons, dtype=np.float64)
    shot = np.where(e < model.full_well_e, e, 0.0)
    g = model.gain
    var = (shot + tail_variance(model) + model.row_noise_e**2) / g**2 + QUANTISATION_VARIANCE
    return var.astype(np.float32)
