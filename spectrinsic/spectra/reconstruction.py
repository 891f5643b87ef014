"""Reconstruction error of the diagonal (K-channel) rendering model, thesis section 5.2.3.

A renderer approximates the sensor response ``p_k = ∫ f L S_k dλ`` (Eq. 4.9) by the product of
separately integrated material and light values, ``p̂_k = (∫ f S_k dλ)(∫ L S_k dλ)`` (Eq. 5.2;
Eq. 5.3 for one bounce) and, after two bounces, ``p̂ = f₂ ∘ f₁ ∘ L`` (the interreflection term
of Eq. 5.6). The error of the approximation is the relative error of Eq. 5.7,
``ε = ‖p − p̂‖₂ / ‖p‖₂`` over the K channels: :func:`relative_error` is its one implementation,
for surfaces here and for pixels of rendered images elsewhere.

Integration is the rectangle rule on the wavelength grid (nm), as in
:func:`spectrinsic.spectra.colorimetry.responses`.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import numpy.typing as npt

from ..arrays import Mask, SensorCurves, SpectralValues, Wavelengths
from .colorimetry import diagonal_values, responses

__all__ = [
    "relative_error",
    "one_bounce_errors",
    "two_bounce_errors",
    "pair_responses",
    "ordered_pairs",
]


def relative_error(
    estimate: npt.ArrayLike,
    reference: npt.ArrayLike,
    *,
    dark_fraction: float = 0.0,
    where: Mask | None = None,
    fill: float = np.nan,
    scale: float = 1.0,
) -> npt.NDArray[np.float64]:
    """Relative error ``ε = ‖p − p̂‖₂ / ‖p‖₂`` over the last axis (thesis Eq. 5.7).

    The dark rule, one for every use of Eq. 5.7: an entry is *dark* when its reference norm
    ``‖p‖₂`` is at most ``dark_fraction`` times the 99th percentile of the positive reference
    norms inside *where*; ε is undefined there and set to *fill*. With the default
    ``dark_fraction = 0`` only black references (``‖p‖₂ = 0``) are dark. Entries outside *where*
    get *fill* too.

    Parameters
    ----------
    estimate, reference
        ``(..., K)`` linear values (not gamma-encoded) of the approximation p̂ and of the
        reference p, in the same units (sensor responses, CIE XYZ...).
    dark_fraction
        Dark threshold as a fraction of the 99th-percentile reference norm (>= 0).
    where
        ``(...)`` bool: the entries to evaluate (default: all).
    fill
        Value of dark and excluded entries (default NaN).
    scale
        Unit of the result: 1 for a fraction (default), 100 for percent.

    Returns
    -------
    ``(...)`` float64, ``scale · ε``.

    >>> p = np.ones((1, 2, 3)); q = p.copy(); q[0, 1] = [1.0, 1.0, 1.3]
    >>> np.round(relative_error(q, p), 4).tolist()
    [[0.0, 0.1732]]
    >>> relative_error(np.ones(3), np.zeros(3), fill=0.0).tolist()
    0.0
    """
    ref = np.asarray(reference, np.float64)
    est = np.asarray(estimate, np.float64)
    norm = np.linalg.norm(ref, axis=-1)
    region = np.ones(norm.shape, bool) if where is None else np.asarray(where, bool)
    floor = 0.0
    if dark_fraction > 0:
        lit = norm[region & (norm > 0)]
        floor = dark_fraction * float(np.percentile(lit, 99)) if lit.size else np.inf
    ok = region & (norm > floor)
    err = np.full(norm.shape, fill, dtype=np.float64)
    err[ok] = scale * np.linalg.norm(est - ref, axis=-1)[ok] / norm[ok]
    return err


def one_bounce_errors(
    reflectances: SpectralValues,
    illuminant: SpectralValues,
    curves: SensorCurves,
    wavelengths: Wavelengths,
    *,
    chip_threshold: float = 0.0,
) -> npt.NDArray[np.float64]:
    """ε (Eq. 5.7, percent) of ``p̂ = f ∘ L`` (Eq. 5.3) against ``p = ∫ f L S`` (Eq. 4.9).

    Parameters
    ----------
    reflectances
        ``(N, W)`` in [0, 1].
    illuminant
        ``(W,)`` relative spectral power.
    curves
        ``(K, W)`` sensor sensitivities.
    wavelengths
        ``(W,)`` nm.
    chip_threshold
        Reflectances whose mean over the grid is below this are left out (a choice of surfaces,
        thesis section 5.2.3, not the dark rule of :func:`relative_error`).

    Returns
    -------
    ``(M,)`` float64 errors in percent, one per kept reflectance.
    """
    f = np.asarray(reflectances, float)
    f = f[f.mean(axis=1) >= chip_threshold]
    exact = responses(f * illuminant, curves, wavelengths)
    approx = diagonal_values(f, curves, wavelengths) * responses(illuminant, curves, wavelengths)
    return relative_error(approx, exact, scale=100.0)


def pair_responses(
    reflectances: SpectralValues,
    illuminant: SpectralValues,
    curves: SensorCurves,
    wavelengths: Wavelengths,
    *,
    pair_threshold: float,
    include_self_pairs: bool,
    chunk_size: int,
) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """Yield ``(i, j, exact, approx)`` for chunks of the kept unordered pairs ``i <= j``.

    ``exact[m, k] = Σ_λ fᵢ fⱼ L S_k Δλ`` (the interreflection term of Eq. 5.6) comes from one
    matrix product per chunk of rows, ``F[rows] @ G`` with ``G[λ, (j, k)] = fⱼ(λ) L(λ) S_k(λ) Δλ``;
    ``approx = fᵢ ∘ fⱼ ∘ L`` (normalised diagonal values, Eq. 5.2). Both are symmetric in (i, j),
    so only ``j > i`` (and ``j == i`` with *include_self_pairs*) is computed;
    :func:`ordered_pairs` expands values to the ordered pairs (f₂, f₁). Pairs whose mean
    ``fᵢ fⱼ`` over the grid is below *pair_threshold* are left out. Arrays: ``i, j`` ``(M,)``
    int, ``exact, approx`` ``(M, K)`` float64 responses in the units of *illuminant* · nm.
    """
    f = np.asarray(reflectances, float)
    s = np.asarray(curves, float)
    n, k = f.shape[0], s.shape[0]
    dl = np.gradient(np.asarray(wavelengths, float))
    g = (
        ((f * (illuminant * dl))[:, :, None] * s.T[None, :, :])
        .transpose(1, 0, 2)
        .reshape(f.shape[1], n * k)
    )
    fs = diagonal_values(f, s, wavelengths)
    ls = responses(illuminant, s, wavelengths)
    mean_product = (f @ f.T) / f.shape[1]
    for start in range(0, n, chunk_size):
        rows = np.arange(start, min(start + chunk_size, n))
        cols = np.arange(start, n)
        keep = mean_product[np.ix_(rows, cols)] >= pair_threshold
        keep &= cols[None, :] >= rows[:, None] + (0 if include_self_pairs else 1)
        r, c = np.nonzero(keep)
        if r.size == 0:
            continue
        exact = (f[rows] @ g[:, start * k :]).reshape(rows.size, cols.size, k)[r, c]
        i, j = rows[r], cols[c]
        yield i, j, exact, fs[i] * fs[j] * ls


def ordered_pairs(values: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Values of unordered pairs repeated once per ordered pair: (i, j) and (j, i) when i ≠ j."""
    return np.concatenate([values, values[i != j]])


def two_bounce_errors(
    reflectances: SpectralValues,
    illuminant: SpectralValues,
    curves: SensorCurves,
    wavelengths: Wavelengths,
    *,
    pair_threshold: float = 0.0,
    include_self_pairs: bool = False,
    chunk_size: int = 128,
) -> npt.NDArray[np.float64]:
    """ε (Eq. 5.7, percent) of ``f₂ ∘ f₁ ∘ L`` against ``∫ f₂ f₁ L S`` over ordered pairs.

    Parameters as :func:`one_bounce_errors`; ``pair_threshold`` discards pairs whose mean
    ``f₁ f₂`` over the grid is below it; ``chunk_size`` rows of reflectances per chunk (memory
    ∝ chunk · N · K). Returns ``(M,)`` float64, one error per kept ordered pair (f₂, f₁) (in no
    particular order).
    """
    out = []
    for i, j, exact, approx in pair_responses(
        reflectances,
        illuminant,
        curves,
        wavelengths,
        pair_threshold=pair_threshold,
        include_self_pairs=include_self_pairs,
        chunk_size=chunk_size,
    ):
        out.append(ordered_pairs(relative_error(approx, exact, scale=100.0), i, j))
    return np.concatenate(out) if out else np.zeros(0)
