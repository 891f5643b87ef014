"""The spectral registry: names, lazy loading, resampling, and one-line errors."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.errors import DataDirectoryError, SpectralDataError, SpectrumNotFoundError
from spectrinsic.spectra import (
    DEFAULT_WAVELENGTHS,
    get_sensors,
    get_spectrum,
    illuminant_set,
    list_spectra,
    wavelength_grid,
)


def test_munsell_by_notation_and_index_agree():
    chip = get_spectrum("munsell:5R 4/14")
    assert chip.name == "munsell:5R 4/14"
    same = get_spectrum("munsell:5.0R 4.0/14.0")
    assert same.name == chip.name and np.array_equal(same.values, chip.values)
    index = list_spectra("munsell").index("munsell:5R 4/14")
    assert np.array_equal(get_spectrum(f"munsell:#{index}").values, chip.values)


def test_munsell_set_is_the_1269_uef_chips():
    names = list_spectra("munsell")
    assert len(names) == 1269 and len(set(names)) == 1269
    chip = get_spectrum(names[0])
    assert chip.wavelengths[0] == 380 and chip.wavelengths[-1] == 800
    # A strong red chip reflects far more at 650 nm than at 450 nm.
    red = get_spectrum("munsell:5R 4/14").on(np.array([450.0, 650.0]))
    assert red[1] > 3 * red[0]


def test_sfu_reflectances_treat_zero_fill_as_missing(data_dir):
    names = list_spectra("sfu", data_dir=data_dir)
    assert len(names) == 1995
    krinov = get_spectrum("sfu:krinov/1", data_dir=data_dir)
    # PROVENANCE.md: Krinov spectra are zero-filled outside 392-776 nm.
    assert krinov.wavelengths[0] == 392 and krinov.wavelengths[-1] == 776
    held = krinov.on(np.array([380.0, 392.0]))
    assert held[0] == held[1] > 0


def test_sfu_without_data_dir_names_the_missing_setting(monkeypatch):
    monkeypatch.delenv("SPECTRINSIC_DATA", raising=False)
    with pytest.raises(DataDirectoryError, match="SPECTRINSIC_DATA"):
        get_spectrum("sfu:munsell/1")


def test_data_dir_without_expected_files(tmp_path):
    with pytest.raises(DataDirectoryError, match="reflect_db_1995.csv"):
        get_spectrum("sfu:munsell/1", data_dir=tmp_path)


@pytest.mark.parametrize(
    "name, message",
    [
        ("munsel:5R 4/14", "did you mean 'munsell'"),
        ("munsell:5R 4/15", "did you mean"),
        ("cie:D66", "did you mean 'D65'"),
        ("colorchecker:dark skn", "did you mean 'dark skin'"),
        ("nonsense", "expected one of"),
    ],
)
def test_unknown_names_suggest_close_matches(name, message):
    with pytest.raises(SpectrumNotFoundError, match=message) as info:
        get_spectrum(name)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("name", ["planck:0K", "planck:-300K"])
def test_non_positive_temperature_is_rejected(name):
    with pytest.raises(SpectralDataError, match="> 0"):
        get_spectrum(name)


def test_illuminants_are_normalised_to_unit_luminance():
    ybar = get_sensors("cie1931").on(DEFAULT_WAVELENGTHS)[1]
    for name in illuminant_set("planckian") + illuminant_set("non-planckian") + ("daylight:5000K",):
        spd = get_spectrum(name).on(DEFAULT_WAVELENGTHS)
        assert np.sum(spd * ybar) / np.sum(ybar) == pytest.approx(1.0, rel=0.02), name


def test_named_illuminant_sets_have_five_each_and_resolve():
    for which in ("planckian", "non-planckian"):
        names = illuminant_set(which)
        assert len(names) == 5
        assert all(get_spectrum(n).kind == "illuminant" for n in names)
    with pytest.raises(Exception, match="did you mean 'planckian'"):
        illuminant_set("plankian")


def test_cameras_builtin_and_from_data_dir(data_dir):
    builtin = list_spectra("camera", data_dir=None)
    assert "camera:Nikon 5100 (NPL)" in builtin
    more = list_spectra("camera", data_dir=data_dir)
    assert "camera:Canon 1DMarkIII" in more and len(more) >= 2 + 28
    cam = get_sensors("camera:Canon 1DMarkIII", data_dir=data_dir)
    assert cam.curves.shape == (3, 33) and cam.curves.min() >= 0
    # Outside the measured 400-720 nm the sensitivity is zero, not extrapolated.
    assert np.all(cam.on(np.array([380.0, 760.0])) == 0)


def test_gaussian_sensors_match_the_table_5_2_design():
    s = get_sensors("gaussian:3@400-700")
    centres = s.wavelengths[np.argmax(s.curves, axis=1)]
    assert np.allclose(centres, [450, 550, 650])
    area = s.curves.sum(axis=1) * 1.0  # 1 nm grid
    assert np.allclose(area, 1.0, atol=1e-6)


def test_box_bands_partition_unity():
    b = get_sensors("bands:31@400-700")
    wl = wavelength_grid(405, 695, 1)
    assert np.allclose(b.on(wl).sum(axis=0), 1.0)


def test_user_csv_sensors_validate(tmp_path):
    good = tmp_path / "good.csv"
    good.write_text("wavelength_nm,R,G\n400,0.1,0.2\n500,0.3,0.4\n600,0.2,0.1\n")
    s = get_sensors(f"csv:{good}")
    assert s.channels == ("R", "G") and s.curves.shape == (2, 3)

    neg = tmp_path / "neg.csv"
    neg.write_text("wavelength_nm,R\n400,0.1\n500,-0.3\n")
    with pytest.raises(SpectralDataError, match=r"neg.csv.*negative.*'R'"):
        get_sensors(f"csv:{neg}")

    dec = tmp_path / "dec.csv"
    dec.write_text("wavelength_nm,R\n500,0.1\n400,0.3\n")
    with pytest.raises(SpectralDataError, match="strictly increasing"):
        get_sensors(f"csv:{dec}")

    empty = tmp_path / "empty.csv"
    empty.write_text("wavelength_nm,R\n")
    with pytest.raises(SpectralDataError, match="empty.csv"):
        get_sensors(f"csv:{empty}")
