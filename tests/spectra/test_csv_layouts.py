"""Issue 47: CSV spectra in the layouts instruments write (wide, wavelength/value pairs, long),
chosen by name or number, with the unit from the header or the name; duplicate names refused.
The fixtures are written here as instruments write them: a UTF-8 BOM, CRLF line ends, a
``Refl. %`` header, pairs of different lengths with empty trailing cells."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from spectrinsic.errors import SpectralDataError
from spectrinsic.spectra import get_spectrum
from spectrinsic.spectra.csv_spectra import layout_of, split_label
from spectrinsic.spectra.user_spectra import spectrum_files

A_WL = np.arange(380.0, 731.0, 10.0)  # 36 rows
B_WL = np.arange(400.0, 701.0, 5.0)  # 61 rows: a finer, shorter scan
A = 0.1 + 0.7 * (A_WL - 380) / 350  # a ramp, in [0.1, 0.8]
B = 0.5 + 0.3 * np.sin(B_WL / 40)


def _instrument_file(path, lines):
    """*lines* joined with CRLF behind a UTF-8 byte-order mark, as a Windows export."""
    path.write_bytes(b"\xef\xbb\xbf" + "\r\n".join(lines).encode("utf-8") + b"\r\n")
    return path


@pytest.fixture
def pairs(tmp_path):
    """Two samples, one wavelength/value pair each, lengths 36 and 61, percent headers."""
    lines = ["Wavelength [nm],Refl. %,Wavelength [nm],Sample B %"]
    for i in range(max(len(A_WL), len(B_WL))):
        a = f"{A_WL[i]:g},{100 * A[i]:.4f}" if i < len(A_WL) else ","
        b = f"{B_WL[i]:g},{100 * B[i]:.4f}" if i < len(B_WL) else ","
        lines.append(f"{a},{b}".rstrip(","))  # the short pair's rows end early: ragged rows
    return _instrument_file(tmp_path / "spectrophotometer.csv", lines)


@pytest.fixture
def long(tmp_path):
    """Two samples as ``sample,wavelength,value`` rows, fractions given by the value header."""
    lines = ["sample,wavelength [nm],value [1]"]
    lines += [f"tile A,{w:g},{v:.6f}" for w, v in zip(A_WL, A)]
    lines += [f"tile B,{w:g},{v:.6f}" for w, v in zip(B_WL, B)]
    return _instrument_file(tmp_path / "database.csv", lines)


def test_headers_state_the_layout_and_the_unit():
    assert layout_of(["wavelength [nm]", "red [%]", "lamp [W/m2/nm]"]) == "wide"
    assert layout_of(["Wavelength [nm]", "Refl. %", "Wavelength [nm]", "Refl. %"]) == "pairs"
    assert layout_of(["sample", "wavelength", "value [%]"]) == "long"
    assert split_label("Refl. %") == ("Refl.", "%")
    assert split_label("lamp (W/m2/nm)") == ("lamp", "W/m2/nm")
    assert split_label("lamp [mW/(m2 nm)]") == ("lamp", "mW/(m2 nm)")
    assert split_label("45") == ("45", None)


def test_pair_layout_reads_each_pair_by_name_and_by_number(pairs):
    first = get_spectrum(f"csv:{pairs}#Refl.")
    by_number = get_spectrum(f"csv:{pairs}#1")
    second = get_spectrum(f"csv:{pairs}#Sample B")
    assert first.kind == second.kind == "reflectance"
    np.testing.assert_array_equal(first.wavelengths, A_WL)  # its 36 rows, no trailing blanks
    np.testing.assert_allclose(first.values, A, atol=1e-6)  # percent divided by 100
    np.testing.assert_array_equal(by_number.values, first.values)
    np.testing.assert_array_equal(second.wavelengths, B_WL)
    np.testing.assert_allclose(second.values, B, atol=1e-6)
    assert get_spectrum(f"csv:{pairs}#2").values.tolist() == second.values.tolist()


def test_long_layout_reads_each_sample(long):
    a = get_spectrum(f"csv:{long}#tile A")
    b = get_spectrum(f"csv:{long}#2")
    np.testing.assert_allclose(a.values, A, atol=1e-6)
    np.testing.assert_array_equal(b.wavelengths, B_WL)
    np.testing.assert_allclose(b.values, B, atol=1e-6)


def test_a_unit_in_the_name_when_the_header_has_none(tmp_path):
    lines = ["nm,R,R2 [%]"] + [f"{w:g},{100 * v:.4f},{100 * v:.4f}" for w, v in zip(A_WL, A)]
    path = _instrument_file(tmp_path / "bare.csv", lines)
    with pytest.raises(SpectralDataError, match="column 'R' has no unit.*#COLUMN\\?unit=%"):
        get_spectrum(f"csv:{path}#R")
    np.testing.assert_allclose(get_spectrum(f"csv:{path}#1?unit=%").values, A, atol=1e-6)
    with pytest.raises(SpectralDataError, match=r"states the unit \[%\], and the name \?unit=1"):
        get_spectrum(f"csv:{path}#2?unit=1")
    (record,) = spectrum_files([f"csv:{path.resolve()}#1?unit=%"])
    assert (record["column"], record["unit"]) == ("1", "%")
    assert record["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()


def test_a_name_two_spectra_share_is_refused_naming_both(tmp_path):
    lines = ["Wavelength [nm],Refl. %,Wavelength [nm],Refl. %"]
    lines += [f"{w:g},{100 * a:.3f},{w:g},{100 * a:.3f}" for w, a in zip(A_WL, A)]
    path = _instrument_file(tmp_path / "twins.csv", lines)
    with pytest.raises(SpectralDataError) as info:
        get_spectrum(f"csv:{path}#Refl.")
    message = str(info.value)
    assert "pair 1 (columns 1-2) and pair 2 (columns 3-4)" in message and "#1" in message
    wide = _instrument_file(
        tmp_path / "wide.csv", ["nm,x [%],x [%]"] + [f"{w:g},50,60" for w in A_WL]
    )
    with pytest.raises(SpectralDataError, match="column 'x' at column 2 and column 3"):
        get_spectrum(f"csv:{wide}#x")
    assert get_spectrum(f"csv:{wide}#2").values[0] == pytest.approx(0.6)


def test_an_empty_value_inside_a_pair_is_refused_naming_its_row(tmp_path):
    lines = ["Wavelength [nm],Refl. %"] + [f"{w:g},50" for w in A_WL]
    lines[5] = f"{A_WL[4]:g},"  # a wavelength without its value
    path = _instrument_file(tmp_path / "hole.csv", lines + ["", "", ""])
    with pytest.raises(SpectralDataError, match="row 6, column 'Refl. %': empty cell"):
        get_spectrum(f"csv:{path}#1")


@pytest.mark.parametrize("layout", ["wide", "pairs", "long"])
def test_a_wavelength_at_or_below_zero_is_refused(tmp_path, layout):
    """Task r5-probe: rows of -5, 400, 700 nm were read as a spectrum (increasing, so every
    check passed); a wavelength is positive, and the first row is the one to name."""
    wl = [-5, 400, 700]
    lines = {
        "wide": ["nm,lamp [1]"] + [f"{w},0.5" for w in wl],
        "pairs": ["nm,lamp [1],nm,other [1]"] + [f"{w},0.5,{w + 10},0.5" for w in wl],
        "long": ["sample,wavelength [nm],value [1]"] + [f"lamp,{w},0.5" for w in wl],
    }[layout]
    path = _instrument_file(tmp_path / "negative.csv", lines)
    with pytest.raises(SpectralDataError, match="row 2, .*wavelength -5 nm; expected positive"):
        get_spectrum(f"csv:{path}#1" if layout != "long" else f"csv:{path}#lamp")
