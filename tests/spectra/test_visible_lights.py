"""Issue 36, cause 6: lights are what they are named, or refused in one line.

``led:200/20`` (UV) and ``led:1000/20`` (IR) were scaled to unit luminance through their 1e-98
Gaussian tails and rendered as deep violet and deep red lights; filters that block everything
visible gave back the lamp's shape through their 1 % leak; a reflectance was accepted as a
filtered light's lamp; ``planck:1K``'s rule caught only exact zeros.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.cli import main
from spectrinsic.errors import SpectrinsicError
from spectrinsic.spectra import get_spectrum
from spectrinsic.spectra.illuminants import VISIBLE_SHARE, visible_share

REFUSED = {
    "led:200/20": "peak 200 nm is outside 360-830 nm",
    "led:1000/20": "peak 1000 nm is outside 360-830 nm",
    "led:460/20@1+1000/20@1": "peak 1000 nm is outside",
    "led:820/20": "visible share",
    "filtered:cie:A|bandpass:900/10": "blocks all the visible light",
    "filtered:cie:A|longpass:800/10": "blocks all the visible light",
    "filtered:cie:A|shortpass:300/10": "blocks all the visible light",
    "filtered:flat:0.5|bandpass:520/80": "'flat:0.5' is a reflectance spectrum",
    "planck:1K": "no power where the eye is sensitive",
    "planck:300K": "visible share",
    "planck:1e400K": "finite number > 0 K",
}
#: Lights near the edges that are what they say: kept.
KEPT = (
    "led:460/20",
    "led:700/20",
    "led:400/20",
    "filtered:cie:A|bandpass:520/80",
    "filtered:cie:A|longpass:650/20",
    "planck:1000K",
    "cie:HP1",
)


@pytest.mark.parametrize("name", list(REFUSED))
def test_a_light_that_is_not_what_it_is_named_is_refused(name):
    with pytest.raises(SpectrinsicError, match=REFUSED[name]) as info:
        get_spectrum(name)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("name", KEPT)
def test_visible_lights_are_kept_with_unit_luminance(name):
    from spectrinsic.spectra.illuminants import VISIBLE_SHARE, visible_share, ybar_at

    s = get_spectrum(name)
    wl = np.asarray(s.wavelengths, float)
    assert visible_share(wl, s.values) >= VISIBLE_SHARE
    # unit luminance-weighted mean (module rule), on the spectrum's own grid
    assert np.sum(s.values * ybar_at(wl)) == pytest.approx(np.sum(ybar_at(wl)), rel=1e-9)


def test_visible_share_of_closed_form_spectra():
    """1 for a line at ȳ's peak (555 nm); ȳ(700 nm)/1 = 0.004102 for a line at 700 nm
    (CIE 1931 table); 0 for a spectrum outside 360-830 nm."""
    from spectrinsic.spectra.illuminants import visible_share

    line = np.array([0.0, 1.0, 0.0])
    assert visible_share(np.array([554.0, 555.0, 556.0]), line) == pytest.approx(1.0)
    assert visible_share(np.array([699.0, 700.0, 701.0]), line) == pytest.approx(0.004102, 1e-3)
    assert visible_share(np.array([900.0, 901.0, 902.0]), line) == 0.0


def test_a_scene_with_an_infrared_led_is_refused_in_one_line(tmp_path, capsys):
    path = tmp_path / "scene.yaml"
    path.write_text(
        'name: quad\nmaterials: {grey: "flat:0.5"}\nmeshes:\n  - name: ground\n'
        "    vertices: [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]\n"
        "    faces: [[0, 1, 2], [0, 2, 3]]\n    material: grey\nlights:\n"
        '  - {kind: point, spectrum: "led:1000/20", power: 4, position: [0, 0, 2]}\n'
        "camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 16, height: 16}\n"
    )
    out = tmp_path / "out"
    assert main(["render", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "lights[0].spectrum" in err and "1000 nm" in err
    assert not out.exists()


def test_a_spectrum_given_by_few_samples_is_judged_between_them():
    # two samples at 380 and 780 nm, where ȳ is almost 0, describe a flat light: its visible
    # share is that of the same light sampled every nanometre (a CSV or inline spectrum)
    wl = np.arange(380.0, 781.0)
    flat = visible_share(wl, np.ones_like(wl))
    assert visible_share(np.array([380.0, 780.0]), np.array([1.0, 1.0])) == pytest.approx(flat)
    assert flat > 100 * VISIBLE_SHARE
