"""A conductor's reflection tint in its band Fresnel table (``fresnel_table(..., tint)``):
the band values of ``F R_t``, checked against a direct quadrature of the product."""

from __future__ import annotations

import numpy as np

from spectrinsic.spectra import get_sensors
from spectrinsic.spectra.conductors import (
    FRESNEL_NODES,
    conductor_ior,
    fresnel_conductor,
    fresnel_table,
)


def test_a_tint_multiplies_the_fresnel_spectrum_before_the_band_integral():
    """A tinted mirror's table is the tint's band values at every μ; a tinted copper's is
    ``Σ F(μ, λ) R_t(λ) S_k(λ) / Σ S_k(λ)`` on a 1 nm grid, not the product of band values
    (which differs by more than the tolerance where F and R_t both vary within a band)."""
    wl = np.arange(360.0, 831.0)
    curves = get_sensors("gaussian:3@450-650").on(wl)
    tint = np.interp(wl, [400.0, 700.0], [0.1, 0.9])
    bands = (curves * tint).sum(axis=1) / curves.sum(axis=1)
    mirror = fresnel_table("none", curves, wl, tint)
    np.testing.assert_allclose(mirror, np.broadcast_to(bands, (FRESNEL_NODES, 3)), rtol=1e-9)
    assert np.all(fresnel_table("none", curves, wl) == 1.0)
    eta, k = conductor_ior("Cu", wl)
    mu = np.linspace(0.0, 1.0, FRESNEL_NODES)
    f = fresnel_conductor(mu[:, None], eta[None, :], k[None, :])
    direct = (f * tint) @ curves.T / curves.sum(axis=1)
    np.testing.assert_allclose(fresnel_table("Cu", curves, wl, tint), direct, rtol=1e-6)
    product = fresnel_table("Cu", curves, wl) * bands
    assert np.abs(product / direct - 1).max() > 1e-3
