"""The photometric model of thesis chapter 4: ``I = L_CLig · S_Sen · (I_Shad ∘ I_Refl^a + I_Spec)``.

3×3 matrices act on column vectors of responses: ``p = M @ q``. ``S_Sen`` maps canonical
(D65, sRGB) values to a camera's values under D65, ``L_CLig`` maps a camera's values under D65 to
its values under the scene light (section 4.4.1), both fitted by least squares.
"""

from __future__ import annotations

import numpy as np

from ..arrays import Matrix3, SensorCurves, Wavelengths
from ..errors import SpectralDataError

__all__ = [
    "ESTIMATE_SCENARIOS",
    "fit_matrix",
    "fit_projection",
    "sharpening_transform",
    "angular_error",
    "scenario_estimates",
]

#: The scenarios of thesis Table 4.3 (section 4.4.1), keys of :func:`scenario_estimates`: what is
#: known when estimating the absolute reflectance ``p^{s,c}`` from camera values ``p``.
ESTIMATE_SCENARIOS: tuple[str, ...] = ("SC1", "SC2", "SC3", "SC4")


def _pairs(src: np.ndarray, dst: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a = np.asarray(src, float).reshape(-1, np.shape(src)[-1])
    b = np.asarray(dst, float).reshape(-1, np.shape(dst)[-1])
    if a.shape[0] != b.shape[0] or a.shape[0] < a.shape[1]:
        raise SpectralDataError(
            f"matrix fit needs as many source as target samples, at least {a.shape[1]}; "
            f"got {a.shape} and {b.shape}"
        )
    return a, b


#: Eigenvalues of the Gram matrix ``aᵀa`` below this fraction of its largest are taken as zero:
#: directions whose singular value is under 1e-6 of the largest carry no information that
#: survives the squared condition number (rounding leaves ~1e-16·λ_max in a zero eigenvalue).
RANK_TOLERANCE: float = 1e-12
#: Cyclic Jacobi sweeps before giving up; a K×K symmetric matrix converges in well under 10.
_JACOBI_SWEEPS = 50


def _symmetric_eigen(gram: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues ``w`` and eigenvectors ``V`` (columns) of a small symmetric matrix.

    Cyclic Jacobi rotations (Golub & Van Loan, Algorithm 8.5.3) in element-wise numpy
    operations only: no BLAS or LAPACK call, so the result is the same bits under every BLAS
    kernel (``OPENBLAS_CORETYPE``), thread count and process.
    """
    g = np.array(gram, dtype=np.float64)
    k = g.shape[0]
    v = np.eye(k)
    scale = float(np.abs(g).max()) or 1.0
    for _ in range(_JACOBI_SWEEPS):
        off = max((abs(g[p, q]) for p in range(k) for q in range(p + 1, k)), default=0.0)
        if off <= 1e-300 or off <= np.finfo(np.float64).eps * 1e-3 * scale:
            break
        for p in range(k - 1):
            for q in range(p + 1, k):
                _jacobi_rotate(g, v, p, q)
    return np.diag(g).copy(), v


def _jacobi_rotate(g: np.ndarray, v: np.ndarray, p: int, q: int) -> None:
    """Zero ``g[p, q]`` in place by the rotation ``Jᵀ g J``, and accumulate ``v ← v J``."""
    if g[p, q] == 0.0:
        return
    theta = (g[q, q] - g[p, p]) / (2.0 * g[p, q])
    t = np.copysign(1.0, theta) / (abs(theta) + np.sqrt(theta * theta + 1.0))
    c = 1.0 / np.sqrt(t * t + 1.0)
    s = t * c
    gp, gq = g[:, p].copy(), g[:, q].copy()
    g[:, p], g[:, q] = c * gp - s * gq, s * gp + c * gq
    gp, gq = g[p, :].copy(), g[q, :].copy()
    g[p, :], g[q, :] = c * gp - s * gq, s * gp + c * gq
    vp, vq = v[:, p].copy(), v[:, q].copy()
    v[:, p], v[:, q] = c * vp - s * vq, s * vp + c * vq


def _least_squares(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The minimum-norm ``X`` minimising ``‖a X − b‖²``: ``X = (aᵀa)⁺ aᵀb``.

    One defined answer also for rank-deficient responses (flat greys make the 6-sensor
    responses exactly rank 1): the pseudo-inverse drops the Gram matrix's eigen-directions
    under :data:`RANK_TOLERANCE` of its largest eigenvalue. The Gram matrices are summed by
    einsum's own loop and decomposed by :func:`_symmetric_eigen`, never by BLAS or LAPACK,
    whose reductions and pivots change with the thread count and CPU kernel (``solve`` raised
    on the singular system under ``OPENBLAS_CORETYPE=Haswell`` and returned noise without it).

    >>> a = np.ones((4, 2)); x = _least_squares(a, 2 * np.ones((4, 1)))  # rank 1
    >>> np.round(x.ravel(), 12).tolist()
    [1.0, 1.0]
    """
    gram = np.einsum("nk,nj->kj", a, a)
    cross = np.einsum("nk,nj->kj", a, b)
    if not (np.isfinite(gram).all() and np.isfinite(cross).all()):
        raise SpectralDataError("least-squares fit of non-finite responses")
    w, v = _symmetric_eigen(gram)
    if w.max(initial=0.0) <= 0.0:
        raise SpectralDataError(
            f"least-squares fit of {a.shape[1]} source channels that are all zero"
        )
    keep = w > RANK_TOLERANCE * w.max()
    inverse = np.where(keep, 1.0 / np.where(keep, w, 1.0), 0.0)
    return np.einsum("ki,i,ji,jm->km", v, inverse, v, cross)


def fit_matrix(src: np.ndarray, dst: np.ndarray, *, diagonal: bool = False) -> Matrix3:
    """Least-squares ``M`` (3×3) with ``dst ≈ src @ M.T`` (i.e. ``p_dst = M p_src``).

    Parameters
    ----------
    src, dst
        ``(N, 3)`` responses of the same surfaces in two conditions.
    diagonal
        Fit a diagonal (von Kries) model ``m_k = Σ src_k dst_k / Σ src_k²`` instead of a full one.

    >>> q = np.random.default_rng(0).random((20, 3)); M = np.diag([2.0, 1.0, 0.5])
    >>> bool(np.allclose(fit_matrix(q, q @ M.T), M))
    True
    """
    a, b = _pairs(src, dst)
    if diagonal:
        return np.diag(np.einsum("nk,nk->k", a, b) / np.einsum("nk,nk->k", a, a))
    return _least_squares(a, b).T


def fit_projection(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """Least-squares linear regression ``P`` (3×K) with ``dst ≈ src @ P.T``.

    Projects K-sensor responses (e.g. the 6 sensors of the thesis' two-pass method) back to
    3 channels (XYZ or linear sRGB), section 5.2.3.
    """
    a, b = _pairs(src, dst)
    return _least_squares(a, b).T


def sharpening_transform(
    curves: SensorCurves,
    wavelengths: Wavelengths,
    *,
    intervals: tuple[tuple[float, float], ...] | None = None,
) -> np.ndarray:
    """Sensor-based spectral sharpening (Finlayson, Drew & Funt 1994), thesis section 4.2.3.

    For each sensor k, the combination ``t_k · S`` with the smallest fraction of its squared
    sensitivity outside the interval ``intervals[k]`` (a generalised eigenproblem). Returns
    ``T`` (K×K) with sharpened curves ``T @ curves``; each row is signed so its curve peaks
    positive. Default intervals split the sensors' joint support into K equal parts.
    """
    from scipy.linalg import eigh

    s = np.asarray(curves, float)
    wl = np.asarray(wavelengths, float)
    k = s.shape[0]
    if intervals is None:
        support = wl[np.any(np.abs(s) > 1e-6 * np.abs(s).max(), axis=0)]
        edges = np.linspace(support.min(), support.max(), k + 1)
        intervals = tuple((edges[i], edges[i + 1]) for i in range(k))
    gram_all = (s * np.gradient(wl)) @ s.T
    t = np.empty((k, k))
    for i, (lo, hi) in enumerate(intervals):
        inside = (wl >= lo) & (wl <= hi)
        gram_in = (s[:, inside] * np.gradient(wl)[inside]) @ s[:, inside].T
        _, vecs = eigh(gram_all - gram_in, gram_all)
        v = vecs[:, 0]
        curve = v @ s
        t[i] = v if curve[np.argmax(np.abs(curve))] > 0 else -v
    return t


def angular_error(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle in degrees between colour vectors (thesis Eq. 4.31): ``acos(a·b / (|a||b|))``.

    >>> float(angular_error(np.array([1.0, 0, 0]), np.array([0, 1.0, 0])))
    90.0
    """
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    num = (a * b).sum(axis=-1)
    den = np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = np.clip(num / den, -1.0, 1.0)
    return np.degrees(np.arccos(cos))


def _solve(m: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``M⁻¹ p`` for row vectors ``p`` (N, 3)."""
    return np.linalg.solve(m, p.T).T


def scenario_estimates(
    p: np.ndarray,
    p_c: np.ndarray,
    p_sc: np.ndarray,
    *,
    p_s: np.ndarray | None = None,
    sc3_light_space: str = "camera",
) -> dict[str, np.ndarray]:
    """Each scenario's estimate of the absolute reflectance ``p^{s,c}`` from ``p`` (Table 4.3).

    The model is Eq. 4.16, ``p = L_CLig · S_Sen · p^{s,c}``. ``S_Sen`` is fitted by least squares
    from ``p^{s,c}`` to ``p^c``, ``L_CLig`` (full, or diagonal ``D``) from ``p^c`` to ``p``
    (:func:`fit_matrix`); each scenario inverts what it knows:

    =====  =======  =======  ===================================================
    name   sensors  light    estimate
    =====  =======  =======  ===================================================
    SC1    known    known    ``S_Sen⁻¹ · L_CLig⁻¹ · p`` (full light model)
    SC2    known    known    ``S_Sen⁻¹ · D⁻¹ · p`` (diagonal light model)
    SC3    unknown  known    ``D⁻¹ · p`` (sRGB sensors assumed: ``S_Sen = Id``)
    SC4    unknown  unknown  ``p`` (D65 and sRGB sensors assumed)
    =====  =======  =======  ===================================================

    With ``sc3_light_space="srgb"`` SC3's ``D`` is fitted between sRGB values under the two
    lights (``p^{s,c}`` to ``p^s``) instead of in the camera's space.

    Parameters
    ----------
    p
        ``(N, 3)`` linear camera responses under the scene light.
    p_c
        ``(N, 3)`` linear camera responses under the canonical light.
    p_sc
        ``(N, 3)`` linear sRGB under the canonical light (the ground truth).
    p_s
        ``(N, 3)`` linear sRGB under the scene light; needed only for ``sc3_light_space="srgb"``.

    Returns
    -------
    ``{"SC1": (N, 3), ..., "SC4": (N, 3)}`` float64, keys :data:`ESTIMATE_SCENARIOS`.
    """
    s_sen = fit_matrix(p_sc, p_c)
    l_full = fit_matrix(p_c, p)
    l_diag = fit_matrix(p_c, p, diagonal=True)
    if sc3_light_space == "srgb":
        if p_s is None:
            raise SpectralDataError(
                "sc3_light_space='srgb' needs the sRGB values under the scene light"
            )
        l_sc3 = fit_matrix(p_sc, p_s, diagonal=True)
    else:
        l_sc3 = l_diag
    return {
        "SC1": _solve(s_sen, _solve(l_full, p)),
        "SC2": _solve(s_sen, _solve(l_diag, p)),
        "SC3": _solve(l_sc3, p),
        "SC4": np.asarray(p, float),
    }
