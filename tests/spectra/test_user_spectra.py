"""A user's spectra: CSV columns with their unit, inline samples, RGB colours (issue 32)."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.errors import SpectralDataError, SpectrinsicError
from spectrinsic.spectra import get_spectrum
from spectrinsic.spectra.user_spectra import (
    REQUIRED_RANGE,
    inline_name,
    portable_csv,
    portable_names,
    spectrum_files,
)

WL = np.arange(380.0, 781.0, 10.0)


def write_csv(path, header, rows):
    path.write_text("\n".join([",".join(header), *(",".join(map(str, r)) for r in rows)]) + "\n")
    return path


@pytest.fixture
def paints(tmp_path):
    red = 0.05 + 0.8 / (1 + np.exp(-(WL - 600) / 15))
    lamp = np.exp(-(((WL - 560) / 120) ** 2)) * 3.0
    rows = [[f"{w:g}", f"{100 * r:.4f}", f"{r:.6f}", f"{p:.6f}"] for w, r, p in zip(WL, red, lamp)]
    header = ["wavelength [nm]", "red [%]", "red fraction [1]", "lamp [W/m2/nm]"]
    return write_csv(tmp_path / "paints.csv", header, rows), red, lamp


def test_a_percent_column_and_a_fraction_column_give_the_same_reflectance(paints):
    path, red, _ = paints
    pct = get_spectrum(f"csv:{path}#red")
    frac = get_spectrum(f"csv:{path}#red fraction [1]")
    assert pct.kind == frac.kind == "reflectance"
    np.testing.assert_allclose(pct.values, red, atol=1e-6)
    np.testing.assert_allclose(frac.values, red, atol=1e-6)


def test_a_power_column_is_an_illuminant_normalised_like_the_others(paints):
    import colour

    path, _, lamp = paints
    light = get_spectrum(f"csv:{path}#lamp")
    assert light.kind == "illuminant"
    ybar = (
        colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
        .copy()
        .align(colour.SpectralShape(380, 780, 10))
    )
    y = ybar.values[:, 1]
    ratio = light.values / lamp
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-5)  # only scaled (6 decimals in the file)
    assert abs((light.values * y).sum() / y.sum() - 1) < 1e-12


@pytest.mark.parametrize(
    ("header", "cells", "expected"),
    [
        (["wl", "a [%]"], {3: ("370", "50")}, "row 5, column 'wl': wavelength 370 nm follows"),
        (["wl", "a [%]"], {5: ("420", "nan")}, "row 7, column 'a [%]': non-finite value 'nan'"),
        (["wl", "a [1]"], {6: ("440", "1.2")}, "row 8 (440 nm): reflectance 1.2 > 1"),
        (["wl", "b [%]"], {}, "no column 'a'; expected one of ['b [%]']"),
        (["wl", "a"], {}, "column 'a' has no unit; expected a header like 'name [%]'"),
        (["wl", "a [%]"], {2: ("400", "")}, "row 4, column 'a [%]': empty cell"),
    ],
)
def test_a_bad_csv_is_refused_in_one_line_naming_file_row_and_column(
    tmp_path, header, cells, expected
):
    rows = [[f"{w:g}", "50" if "%" in header[1] else "0.5"] for w in WL]
    for i, cell in cells.items():
        rows[i] = list(cell)
    path = write_csv(tmp_path / "bad.csv", header, rows)
    with pytest.raises(SpectralDataError) as info:
        get_spectrum(f"csv:{path}#a")
    message = str(info.value)
    assert expected in message and str(path) in message and "\n" not in message


def test_a_csv_not_covering_the_rendering_range_is_refused(tmp_path):
    rows = [[f"{w:g}", "0.5"] for w in WL if w <= 650]
    path = write_csv(tmp_path / "short.csv", ["wl", "a [1]"], rows)
    with pytest.raises(SpectralDataError, match="380-650 nm; expected them to cover 400-700"):
        get_spectrum(f"csv:{path}#a")


def test_required_range_weight():
    """The figures REQUIRED_RANGE's comment quotes: CMF weight outside 400-700 nm."""
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wl, v = cmfs.wavelengths, cmfs.values
    inside = (wl >= REQUIRED_RANGE[0]) & (wl <= REQUIRED_RANGE[1])
    outside = 1 - v[inside].sum(0) / v.sum(0)
    np.testing.assert_allclose(outside, [0.0025, 0.00057, 0.0049], rtol=0.05)


def test_inline_spectra_are_checked_like_file_ones():
    name = inline_name([400, 550, 700], [0.2, 0.4, 0.6], "reflectance")
    s = get_spectrum(name)
    assert s.kind == "reflectance" and s.on(np.array([475.0]))[0] == pytest.approx(0.3)
    for wl, v, match in (
        ([400, 700, 550], [0.2, 0.4, 0.6], "strictly increasing"),
        ([400, 550, 700], [0.2, 1.4, 0.6], "reflectance 1.4 > 1"),
        ([450, 550, 700], [0.2, 0.4, 0.6], "expected them to cover 400-700"),
    ):
        with pytest.raises(SpectralDataError, match=match):
            get_spectrum(inline_name(wl, v, "reflectance"))


def test_spectrum_files_records_the_hash_of_each_file(paints):
    import hashlib

    path, _, _ = paints
    name = get_spectrum(f"csv:{path}#red").name
    (record,) = spectrum_files([name, name, "munsell:5R 4/14"])
    assert record["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
    # no folder given: the file by its name (no absolute path is recorded)
    assert record["column"] == "red" and record["file"] == path.name
    (inside,) = spectrum_files([name], path.parent.parent)  # relative to the scene's folder
    assert inside["file"] == f"{path.parent.name}/{path.name}"
    assert inside["spectrum"] == f"csv:{path.parent.name}/{path.name}#red"


def test_portable_csv_names_files_relative_to_the_scene_folder(tmp_path):
    """Relative to *base* when inside it, else the file name; a sensor set (no column) by its
    file name; a relative name and other families as they are."""
    base = tmp_path / "scene"
    assert portable_csv(f"csv:{base}/sub/p.csv#red [%]", base) == "csv:sub/p.csv#red [%]"
    assert portable_csv(f"csv:{tmp_path}/elsewhere/p.csv#3?unit=%", base) == "csv:p.csv#3?unit=%"
    sensors = f"csv:{base}/cam.csv"  # a sensor set (it names camera layers): its file name
    assert portable_csv(sensors, base) == "csv:cam.csv"
    assert portable_csv("csv:sub/cam.csv", base) == "csv:sub/cam.csv"
    assert portable_csv("csv:sub/p.csv#red", base) == "csv:sub/p.csv#red"
    assert portable_csv("munsell:5R 4/14", base) == "munsell:5R 4/14"
    record = {"lights": [{"spectrum": f"csv:{base}/l.csv#lamp", "power": 2.0}], "n": 1}
    assert portable_names(record, base) == {
        "lights": [{"spectrum": "csv:l.csv#lamp", "power": 2.0}],
        "n": 1,
    }


def _srgb_under_d65(values: np.ndarray, wl: np.ndarray) -> np.ndarray:
    """Linear sRGB of a reflectance under D65 by colour-science (white Y = 1)."""
    import colour

    sd = colour.SpectralDistribution(dict(zip(wl, values)))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(sd.shape)
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(sd.shape)
    xyz = colour.sd_to_XYZ(sd, cmfs, d65, method="Integration") / 100
    return colour.XYZ_to_RGB(xyz, "sRGB", apply_cctf_encoding=False)


def test_rgb_round_trips_through_its_spectrum_within_1e_3():
    """sRGB -> spectrum -> sRGB under D65 on a 5^3 grid of in-gamut colours (issue 32)."""
    grid = np.linspace(0, 1, 5)
    worst = 0.0
    for rgb in np.stack(np.meshgrid(grid, grid, grid), -1).reshape(-1, 3):
        s = get_spectrum("rgb:" + ",".join(f"{c:.17g}" for c in rgb))
        assert s.kind == "reflectance" and 0 <= s.values.min() and s.values.max() <= 1
        worst = max(worst, float(np.abs(_srgb_under_d65(s.values, s.wavelengths) - rgb).max()))
    assert worst < 1e-3, worst


def test_srgb_decodes_before_the_uplift_and_refuses_out_of_gamut():
    import colour

    encoded = get_spectrum("srgb:#cc3311")
    linear = colour.cctf_decoding(np.array([0xCC, 0x33, 0x11]) / 255, function="sRGB")
    np.testing.assert_allclose(
        _srgb_under_d65(encoded.values, encoded.wavelengths), linear, atol=1e-3
    )
    with pytest.raises(SpectrinsicError, match="outside the sRGB gamut"):
        get_spectrum("rgb:1.2,0,0")


def test_daylight_by_cct_has_the_cie_d_series_chromaticity():
    """``daylight:T`` against colour-science: its xy (CIE 1931 2°) within 2e-4 of the CIE
    D-series locus at T (measured <= 1.4e-4 for 4000-25000 K), and 6504 K within 1e-4 of the
    tabulated D65 (measured 3.3e-5)."""
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]

    def xy(name):
        s = get_spectrum(name)
        sd = colour.SpectralDistribution(dict(zip(s.wavelengths, s.values)))
        return colour.XYZ_to_xy(colour.sd_to_XYZ(sd, cmfs))

    for t in (4000, 6500, 25000):
        locus = colour.temperature.CCT_to_xy_CIE_D(t)
        assert np.abs(xy(f"daylight:{t}K") - locus).max() < 2e-4
    assert np.abs(xy("daylight:6504K") - xy("cie:D65")).max() < 1e-4


def test_the_primaries_round_trip_within_the_documented_worst_on_our_colorimetry():
    """Issue 47: the figure the docs quote is the worst over the grid and the primaries on the
    reflectance layer's own 1 nm colorimetry: 1.2e-3, at the blue primary."""
    from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS, get_sensors
    from spectrinsic.spectra.colorimetry import white_normalised_responses
    from spectrinsic.spectra.working_space import working_space

    wl = COLORIMETRIC_WAVELENGTHS
    cmfs, d65 = get_sensors("cie1931").on(wl), get_spectrum("cie:D65").on(wl)
    errors = {}
    for rgb in np.eye(3):
        s = get_spectrum("rgb:" + ",".join(f"{c:g}" for c in rgb))
        xyz = white_normalised_responses(s.on(wl), d65, cmfs, wl)
        errors[tuple(rgb)] = float(np.abs(working_space("srgb").rgb(xyz) - rgb).max())
    assert max(errors.values()) < 1.3e-3
    assert max(errors, key=errors.get) == (0.0, 0.0, 1.0)


def test_a_recorded_sensor_csv_is_read_from_the_folder_that_holds_it(tmp_path):
    """``csv:cam.csv`` (recorded by file name): in the folder when it holds the file, else as
    given (the working folder); an absolute name (an older sample) as it is."""
    from spectrinsic.spectra.user_spectra import readable_sensor_csv

    assert readable_sensor_csv("csv:cam.csv", tmp_path) == "csv:cam.csv"  # not there
    (tmp_path / "cam.csv").write_text("wavelength [nm],R,G,B\n")
    assert readable_sensor_csv("csv:cam.csv", tmp_path) == f"csv:{tmp_path / 'cam.csv'}"
    assert readable_sensor_csv("csv:cam.csv", None) == "csv:cam.csv"
    assert readable_sensor_csv("csv:/old/cam.csv", tmp_path) == "csv:/old/cam.csv"
