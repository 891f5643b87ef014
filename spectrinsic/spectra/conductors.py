"""Conductors: Mitsuba's measured spectral η and k, their Fresnel reflectance, and its band values.

A metal reflects only through its specular lobe, whose colour is the unpolarised Fresnel
reflectance of the complex index ``η + i k`` (Mitsuba's ``fresnel_conductor``)::

    F(μ, λ) = ½ (R_s + R_p),   μ = cos θ_i between the incident direction and the microfacet
    normal (the surface normal for a smooth metal).

A diagonal band render cannot carry F(μ, λ) itself, so it carries its band values as a table
over μ: ``F_k(μ_j) = ∫ F(μ_j, λ) S_k dλ / ∫ S_k dλ`` (Eq. 5.4, as a material's band albedo),
on :data:`FRESNEL_NODES` equally spaced μ in [0, 1], interpolated linearly by the renderer.
At normal incidence ``F(1, λ) = ((η − 1)² + k²) / ((η + 1)² + k²)``.

:data:`PERFECT_MIRROR` (``none``, Mitsuba's name) is the ideal mirror, F = 1 at every μ and λ.
"""

from __future__ import annotations

import functools

import numpy as np

from ..arrays import SensorCurves, Wavelengths
from ..errors import SpectralDataError, did_you_mean
from .colorimetry import diagonal_values
from .io import mitsuba_ior_dir, read_conductor_ior

__all__ = [
    "FRESNEL_NODES",
    "PERFECT_MIRROR",
    "conductor_names",
    "check_conductor",
    "conductor_ior",
    "fresnel_conductor",
    "fresnel_table",
]

#: Number of equally spaced μ = cos θ nodes of a band Fresnel table (0 and 1 included).
FRESNEL_NODES = 65
#: Mitsuba's ``material`` of a perfect mirror (``conductor`` with F = 1).
PERFECT_MIRROR = "none"


@functools.cache
def conductor_names() -> tuple[str, ...]:
    """Names of the conductors Mitsuba ships η and k for (``Ag``, ``Al``, ``Au``, ``Cu``...)."""
    folder = mitsuba_ior_dir()
    eta = {p.name.removesuffix(".eta.spd") for p in folder.glob("*.eta.spd")}
    k = {p.name.removesuffix(".k.spd") for p in folder.glob("*.k.spd")}
    return tuple(sorted(eta & k))


def check_conductor(name: str, what: str = "metal") -> str:
    """*name* if Mitsuba ships its η/k tables, else a one-line :class:`SpectralDataError`."""
    names = conductor_names()
    if name not in names and name != PERFECT_MIRROR:
        raise SpectralDataError(
            f"{what}: unknown conductor {name!r}; expected one of Mitsuba's "
            f"tables such as Ag, Al, Au, Cu, Cr, W, or {PERFECT_MIRROR!r} (a perfect mirror)"
            + did_you_mean(name, names)
        )
    return name


def conductor_ior(name: str, wavelengths: Wavelengths) -> tuple[np.ndarray, np.ndarray]:
    """η(λ) and k(λ) of conductor *name* on *wavelengths* (nm), linear interpolation of
    Mitsuba's table (held constant beyond its ends)."""
    table = read_conductor_ior(check_conductor(name))
    wl = np.asarray(wavelengths, float)
    return (
        np.interp(wl, table.wavelengths, table.values[0]),
        np.interp(wl, table.wavelengths, table.values[1]),
    )


def fresnel_conductor(mu: np.ndarray, eta: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Unpolarised Fresnel reflectance of a conductor ``η + i k`` seen from a medium of index 1
    at cosine *mu* (broadcast), the full formula of Mitsuba's ``fresnel_conductor``.

    >>> round(float(fresnel_conductor(np.array(1.0), np.array(1.5), np.array(0.0))), 6)
    0.04
    """
    c = np.clip(np.asarray(mu, float), 0.0, 1.0)
    eta, k = np.asarray(eta, float), np.asarray(k, float)
    c2, s2 = c * c, 1.0 - c * c
    a = eta * eta - k * k - s2
    a2b2 = np.sqrt(a * a + 4.0 * eta * eta * k * k)
    t_a = np.sqrt(np.maximum(0.5 * (a2b2 + a), 0.0))
    t1, t2 = a2b2 + c2, 2.0 * c * t_a
    r_s = (t1 - t2) / (t1 + t2)
    t3, t4 = c2 * a2b2 + s2 * s2, t2 * s2
    r_p = r_s * (t3 - t4) / np.where(t3 + t4 > 0.0, t3 + t4, 1.0)
    return 0.5 * (r_s + r_p)


def fresnel_table(
    name: str, curves: SensorCurves, wavelengths: Wavelengths, tint: np.ndarray | None = None
) -> np.ndarray:
    """``(FRESNEL_NODES, K)`` band Fresnel values ``F_k(μ_j)`` of conductor *name* for the
    sensor *curves* ``(K, W)`` on *wavelengths* (module docstring); with *tint* ``(W,)``, a
    reflection tint R_t(λ) (Mitsuba's ``specular_reflectance``), those of ``F R_t``."""
    if np.ndim(curves) != 2:
        raise SpectralDataError(
            f"fresnel_table({name!r}): expected (K, W) sensor curves, got {np.shape(curves)}"
        )
    if name == PERFECT_MIRROR and tint is None:
        return np.ones((FRESNEL_NODES, np.shape(curves)[0]))
    mu = np.linspace(0.0, 1.0, FRESNEL_NODES)
    if name == PERFECT_MIRROR:
        spectra = np.ones((FRESNEL_NODES, np.size(wavelengths)))
    else:
        eta, k = conductor_ior(name, wavelengths)
        spectra = fresnel_conductor(mu[:, None], eta[None, :], k[None, :])
    return diagonal_values(spectra * (1.0 if tint is None else tint), curves, wavelengths)
