"""Colorimetry checked against colour-science and closed-form physics."""

from __future__ import annotations

from pathlib import Path

import colour
import numpy as np
import pytest
from scipy import constants

from spectrinsic.spectra import (
    COLORIMETRIC_WAVELENGTHS,
    absolute_reflectance,
    angular_error,
    diagonal_values,
    fit_matrix,
    fit_projection,
    gaussian_sensors,
    get_sensors,
    get_spectrum,
    planck_law,
    responses,
    sharpening_transform,
    wavelength_grid,
    xyz_to_linear_srgb,
    xyz_to_xy,
)

#: Agreement with colour-science when both integrate the same data on the same grid.
EXACT = 1e-9


def test_planck_law_at_a_known_point():
    # Eq. B.1 evaluated by hand, radiance form: c1 = 2*h*c^2 (CODATA) and the CIE 015:2018
    # value c2 = 1.4388e-2 m K (the ITS-90 convention colorimetry uses, not CODATA's hc/k).
    lam, t = 500e-9, 5000.0
    c1 = 2 * constants.h * constants.c**2
    c2 = 1.4388e-2
    expected = c1 / lam**5 / np.expm1(c2 / (lam * t))
    assert planck_law(np.array([500.0]), t)[0] == pytest.approx(expected, rel=1e-6)


def test_planckian_peak_follows_wien():
    # Wien's displacement law: lambda_max = b / T (b = 2.897771955e-3 m K).
    wl = wavelength_grid(300, 2000, 0.5)
    peak = wl[np.argmax(planck_law(wl, 3000.0))]
    assert peak == pytest.approx(constants.Wien / 3000.0 * 1e9, abs=1.0)


@pytest.mark.parametrize("d", ["D50", "D65", "D75"])
def test_perfect_white_under_d_series_has_its_chromaticity(d):
    wl = COLORIMETRIC_WAVELENGTHS
    cmf = get_sensors("cie1931").on(wl)
    white = get_spectrum("flat:1").on(wl)
    xy = xyz_to_xy(responses(white * get_spectrum(f"cie:{d}").on(wl), cmf, wl))
    expected = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"][d]
    assert np.allclose(xy, expected, atol=2e-4)


def test_munsell_under_d65_matches_colour_sd_to_xyz():
    chip = get_spectrum("munsell:5R 4/14")
    shape = colour.SpectralShape(360, 830, 1)
    sd = colour.SpectralDistribution(dict(zip(chip.wavelengths, chip.values))).copy()
    sd = sd.align(shape, extrapolator_kwargs={"method": "Constant", "left": None, "right": None})
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    reference = colour.sd_to_XYZ(sd, cmfs, d65, method="Integration") / 100
    ours = absolute_reflectance(chip)
    assert np.allclose(ours, colour.XYZ_to_sRGB(reference, apply_cctf_encoding=False), atol=1e-4)


def test_srgb_sensors_equal_xyz_then_matrix():
    wl = COLORIMETRIC_WAVELENGTHS
    spd = get_spectrum("munsell:5B 6/8").on(wl) * get_spectrum("cie:A").on(wl)
    via_xyz = xyz_to_linear_srgb(responses(spd, get_sensors("cie1931").on(wl), wl))
    direct = responses(spd, get_sensors("srgb").on(wl), wl)
    assert np.allclose(via_xyz, direct, rtol=EXACT, atol=EXACT)


def test_diagonal_values_are_scale_invariant():
    wl = wavelength_grid(400, 700, 5)
    s = gaussian_sensors(6, 400, 700, wavelengths=wl).curves
    rho = get_spectrum("munsell:5G 5/8").on(wl)
    assert np.allclose(diagonal_values(rho, s, wl), diagonal_values(rho, 7.0 * s, wl))
    assert np.allclose(diagonal_values(np.full(wl.size, 0.3), s, wl), 0.3)


def test_diagonal_model_error_vanishes_as_sensors_narrow():
    """(∫fS)(∫LS)/∫S -> ∫fLS as the sensors tend to delta functions."""
    wl = wavelength_grid(400, 700, 1)
    rho = get_spectrum("munsell:5PB 4/10").on(wl)
    light = get_spectrum("cie:FL2").on(wl)
    errors = []
    for sigma in (30.0, 10.0, 3.0, 1.0):
        s = gaussian_sensors(3, 400, 700, sigma=sigma, wavelengths=wl).curves
        exact = responses(rho * light, s, wl)
        approx = diagonal_values(rho, s, wl) * responses(light, s, wl)
        errors.append(np.linalg.norm(exact - approx) / np.linalg.norm(exact))
    assert all(b < a for a, b in zip(errors, errors[1:]))
    assert errors[-1] < 0.01 * errors[0]


def test_fit_matrix_recovers_a_known_transform():
    rng = np.random.default_rng(1)
    q = rng.random((200, 3))
    m = np.array([[0.9, 0.2, -0.05], [0.1, 1.1, 0.0], [0.02, -0.1, 0.8]])
    assert np.allclose(fit_matrix(q, q @ m.T), m, atol=1e-12)
    d = np.diag([1.5, 1.0, 0.6])
    assert np.allclose(fit_matrix(q, q @ d.T, diagonal=True), d, atol=1e-12)
    p = rng.random((3, 6))
    q6 = rng.random((100, 6))
    assert np.allclose(fit_projection(q6, q6 @ p.T), p, atol=1e-12)


def test_sharpening_narrows_overlapping_sensors():
    wl = wavelength_grid(400, 700, 1)
    s = get_sensors("cie1931").on(wl)
    t = sharpening_transform(s, wl)
    sharp = t @ s

    def outside_fraction(curves):
        edges = np.linspace(400, 700, 4)
        out = []
        for k, c in enumerate(curves):
            inside = (wl >= edges[k]) & (wl <= edges[k + 1])
            out.append(np.sum(c[~inside] ** 2) / np.sum(c**2))
        return np.array(out)

    order = np.argsort(wl[np.argmax(s, axis=1)])  # z, y, x by peak wavelength
    assert np.all(outside_fraction(sharp) <= outside_fraction(s[order]) + 1e-9)


def test_angular_error_closed_forms():
    assert angular_error(np.array([1.0, 1, 1]), np.array([2.0, 2, 2])) == pytest.approx(
        0.0, abs=1e-6
    )
    assert angular_error(np.array([1.0, 0, 0]), np.array([1.0, 1, 0])) == pytest.approx(45.0)


@pytest.mark.slow
def test_fits_and_responses_do_not_depend_on_blas_threads(tmp_path):
    """The fitted matrices written to meta.json come out bit-identical with 1 and 2 BLAS threads
    (issue 9, point 10): responses and least squares avoid threaded BLAS reductions."""
    import subprocess
    import sys

    script = tmp_path / "fit.py"
    script.write_text(
        "import numpy as np\n"
        "from spectrinsic.spectra import fit_matrix, fit_projection, family_values, responses\n"
        "from spectrinsic.spectra import get_sensors, COLORIMETRIC_WAVELENGTHS as wl\n"
        "rho = family_values('munsell', wl)\n"
        "q = responses(rho, get_sensors('srgb').on(wl), wl)\n"
        "p = responses(rho, get_sensors('gaussian:6@400-700').on(wl), wl)\n"
        "out = np.concatenate([fit_matrix(q, np.abs(q[:, ::-1]) ** 1.1).ravel(), fit_projection(p, q).ravel(), q.ravel()])\n"
        "print(out.tobytes().hex())\n"
    )
    outputs = set()
    for env in _blas_environments():
        run = subprocess.run(
            [sys.executable, "-P", str(script)], capture_output=True, text=True, env=env, check=True
        )
        outputs.add(run.stdout)
    assert len(outputs) == 1


def _blas_environments() -> list[dict[str, str]]:
    """This process's environment with 1 and 2 BLAS threads, and with OpenBLAS's CPU kernel
    forced to Haswell and left to its own choice (some CI machines set it), where the CPU can
    run Haswell's AVX2 kernels."""
    import os

    base = {k: v for k, v in os.environ.items() if not k.startswith("OPENBLAS_")}
    envs = [{**base, "OPENBLAS_NUM_THREADS": n, "OMP_NUM_THREADS": n} for n in ("1", "2")]
    cpu = Path("/proc/cpuinfo")
    if cpu.is_file() and " avx2" in cpu.read_text():
        envs.append({**base, "OPENBLAS_CORETYPE": "Haswell", "OPENBLAS_NUM_THREADS": "2"})
    return envs


def test_rank_deficient_fit_is_the_minimum_norm_solution_under_every_blas_kernel(tmp_path):
    """Exactly rank-deficient responses (flat greys seen by 6 sensors are rank 1) get one
    defined answer, the minimum-norm least-squares solution (independent reference: numpy's
    SVD ``lstsq``), bit-identical whatever BLAS kernel or thread count the process runs."""
    import subprocess
    import sys

    from spectrinsic.spectra import fit_projection

    rng = np.random.default_rng(5)
    greys = np.linspace(0.15, 0.95, 12)[:, None]
    a = greys * rng.random(6)  # every row a multiple of one 6-sensor response: rank 1
    b = greys * rng.random(3)
    ref, *_ = np.linalg.lstsq(a, b, rcond=1e-8)
    np.testing.assert_allclose(fit_projection(a, b), ref.T, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(a @ fit_projection(a, b).T, b, rtol=1e-12)
    script = tmp_path / "rank.py"
    script.write_text(
        "import numpy as np\n"
        "from spectrinsic.spectra import fit_projection\n"
        "rng = np.random.default_rng(5); g = np.linspace(0.15, 0.95, 12)[:, None]\n"
        "a = g * rng.random(6); b = g * rng.random(3)\n"
        "print(fit_projection(a, b).tobytes().hex())\n"
    )
    outputs = {
        subprocess.run(
            [sys.executable, "-P", str(script)], capture_output=True, text=True, env=env, check=True
        ).stdout
        for env in _blas_environments()
    }
    assert len(outputs) == 1


def test_normal_equations_agree_with_lstsq():
    """Independent reference: numpy's SVD least squares."""
    from spectrinsic.spectra import fit_projection

    rng = np.random.default_rng(3)
    a = rng.random((500, 6))
    b = a @ rng.random((6, 3)) + 1e-3 * rng.standard_normal((500, 3))
    ref, *_ = np.linalg.lstsq(a, b, rcond=None)
    np.testing.assert_allclose(fit_projection(a, b), ref.T, rtol=1e-10, atol=1e-12)
