"""Issue 48, round 7: the image's fine detail that a shading holds goes back to the reflectance.

Independent values: analytic images ``I = R S`` with a known reflectance (fine print, ratio
2 or 16) and a known shading (a smooth light gradient and a soft cast shadow, x 0.25 with a
10-pixel smoothstep penumbra), never the method's own output. Where the step must act, the
shading it starts from reproduces the image's texture (the print or the sensor's noise);
where it must not, the shading is the true one and stays.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.decompose.decomposition import Decomposition
from spectrinsic.decompose.methods.names_shades import NamesAndShades
from spectrinsic.decompose.methods.shading_texture import return_fine_detail, texture_share

N = 48


def _shading() -> np.ndarray:
    """A light falling from 1 to 0.5 across the image and a soft cast shadow (x 0.25, a
    10-pixel smoothstep penumbra) over its right part."""
    y, x = np.mgrid[0:N, 0:N].astype(float)
    t = np.clip((x - N * 0.6) / 10.0 + 0.5, 0.0, 1.0)
    return (1.0 - 0.5 * y / N) * (1.0 - 0.75 * t * t * (3.0 - 2.0 * t))


def _stripes() -> np.ndarray:
    """Print: 2-pixel stripes of 0.8 and 0.4 (ratio 2)."""
    x = np.arange(N)
    return np.tile(np.where((x // 2) % 2 == 0, 0.8, 0.4), (N, 1))


def _away_from_the_penumbra() -> np.ndarray:
    """Pixels 4 or more from the border and from the penumbra (x 23.8 to 33.8)."""
    x = np.arange(N)
    return _interior() & ((x < 20) | (x > 38))[None, :]


def _rgb(a: np.ndarray) -> np.ndarray:
    return np.repeat(a[:, :, None], 3, axis=2)


def _decomposition(refl: np.ndarray, shade: np.ndarray) -> Decomposition:
    return Decomposition(_rgb(refl).astype(np.float32), _rgb(shade).astype(np.float32))


def _interior() -> np.ndarray:
    """Pixels 4 or more from the image's border (the Gaussian's reach is about 2 sigma)."""
    inside = np.zeros((N, N), bool)
    inside[4:-4, 4:-4] = True
    return inside


def test_a_shading_that_holds_the_print_gives_it_back_to_the_reflectance() -> None:
    refl, shade = _stripes(), _shading()
    image, mask = _rgb(refl * shade), np.ones((N, N), bool)
    collapsed = _decomposition(np.ones((N, N)), refl * shade)  # the print in the shading
    out = return_fine_detail(collapsed, image, mask)
    r, s = out.reflectance.mean(axis=2), out.shading.mean(axis=2)
    inside = _away_from_the_penumbra()
    # the stripes (ratio 2) are back in the reflectance within 15 % ...
    light, dark = inside & (refl == 0.8), inside & (refl == 0.4)
    assert abs(np.log(np.median(r[light]) / np.median(r[dark]) / 2.0)) < np.log(1.15)
    # ... and the shading is the light's, up to one scale, within 10 % away from the penumbra
    ratio = s[inside] / shade[inside]
    assert np.max(np.abs(np.log(ratio / np.median(ratio)))) < np.log(1.10)
    report = out.info["texture"]
    assert report["shading_share_before"] > 0.99 and report["shading_share_after"] < 0.2
    assert report["action"] == "smoothed" and "approximation" in report["detail"]


def test_a_true_shading_with_a_soft_shadow_stays() -> None:
    refl, shade = _stripes(), _shading()
    image, mask = _rgb(refl * shade), np.ones((N, N), bool)
    assert abs(texture_share(image, _rgb(shade), mask).shading_share) < 0.05
    out = return_fine_detail(_decomposition(refl, shade), image, mask)
    s = out.shading.mean(axis=2)
    inside = _interior()
    away = _away_from_the_penumbra()
    # the soft shadow (x 0.25) and the light's gradient stay in the shading within 3 % away
    # from the penumbra; in it the Gaussian rounds the ramp's dark foot (17 % measured)
    assert np.max(np.abs(np.log(s[away] / shade[away]))) < np.log(1.03)
    assert np.max(np.abs(np.log(s[inside] / shade[inside]))) < np.log(1.25)
    assert abs(out.info["texture"]["shading_share_before"]) < 0.05


def test_sensor_noise_left_in_the_shading_goes_to_the_reflectance() -> None:
    """One colour per region (names-and-shades' reflectance) leaves 5 % multiplicative noise
    in the shading; returned to the reflectance, the shading is much closer to the true one."""
    refl, shade = _stripes(), _shading()
    noise = 1.0 + 0.05 * np.random.default_rng(7).standard_normal((N, N))
    image, mask = _rgb(refl * shade * noise), np.ones((N, N), bool)
    out = return_fine_detail(_decomposition(refl, shade * noise), image, mask)
    away = _away_from_the_penumbra()

    def error(s: np.ndarray) -> float:
        return float(np.sqrt(np.mean(np.log(s[away] / shade[away]) ** 2)))

    assert error(shade * noise) > 0.04  # the noise itself
    assert error(out.shading.mean(axis=2)) < 0.4 * error(shade * noise)
    report = out.info["texture"]
    assert 0.0 < report["shading_share_after"] < report["shading_share_before"]


@pytest.mark.filterwarnings("ignore::FutureWarning")  # gco's numpy aliases
def test_names_shades_reports_what_it_moved() -> None:
    image = _rgb((_stripes() * _shading())[:16, :16])
    report = NamesAndShades()(image).info["texture"]
    assert report["action"] == "smoothed" and report["sigma_px"] == 2.0
    assert report["shading_share_after"] <= report["shading_share_before"]
    assert "texture" not in NamesAndShades(fine_detail=False)(image).info
