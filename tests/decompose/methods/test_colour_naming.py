"""The Benavente et al. (2008) colour-naming model and the Appendix A label set."""

from __future__ import annotations

import hashlib
from importlib import resources

import numpy as np
import pytest

from spectrinsic.decompose.methods import colour_naming as cn

#: Focal examples of the 11 basic terms, as sRGB (8-bit) values of W3C CSS Color Module Level 4
#: named colours (https://www.w3.org/TR/css-color-4/#named-colors), one per term: the keyword
#: itself where it exists, except three colours that are gamut corners rather than focal
#: colours: sRGB primary "red" (#FF0000, CIELab hue 40 deg, on this model's red/orange border),
#: "blue" (#0000FF, named purple by this model, as data/PROVENANCE.md section 5 notes) and
#: "brown" (#A52A2A, a dark red). For those, "crimson", "royalblue" (= (65, 105, 225), which
#: PROVENANCE lists as a blue) and "saddlebrown".
FOCAL_SRGB8 = {
    "black": (0, 0, 0),  # black
    "white": (255, 255, 255),  # white
    "red": (220, 20, 60),  # crimson
    "green": (0, 128, 0),  # green
    "yellow": (255, 255, 0),  # yellow
    "blue": (65, 105, 225),  # royalblue
    "brown": (139, 69, 19),  # saddlebrown
    "purple": (128, 0, 128),  # purple
    "orange": (255, 165, 0),  # orange
    "pink": (255, 192, 203),  # pink
    "grey": (128, 128, 128),  # grey
}
#: The raw model's memberships sum to >= 1; fuzzy chromatic sets overlap near the achromatic
#: centre, reaching ~1.18 (measured on a 21^3 sRGB grid).
RAW_SUM_MAX = 1.2
#: Share of the sRGB cube where the raw sum is within 1e-2 of 1 must exceed this.
RAW_SUM_CLOSE_SHARE = 0.95
#: sha256 of the package data, as data/SOURCES.md lists them.
CHECKSUMS = {
    "benavente2008_tse_chromatic.csv": "54f6316c85fdc6162d77de7af95e758c022fac4037fa5db13bcb7e95f735ef0e",
    "benavente2008_tse_achromatic.csv": "44e1c5a6766fdd7277857079bcbf7a780f5d412040e9b100e5611eabe3448c7a",
}


def test_package_data_checksums():
    for name, digest in CHECKSUMS.items():
        data = resources.files("spectrinsic.decompose").joinpath("data", name).read_bytes()
        assert hashlib.sha256(data).hexdigest() == digest, name
    text = resources.files("spectrinsic.decompose").joinpath("data", "SOURCES.md").read_text()
    assert all(d in text for d in CHECKSUMS.values())
    assert "25(10):2582" in text


def test_parameters_match_shared_data_when_present(data_dir):
    import csv

    src = data_dir / "colour_naming_benavente2008_tse" / "tse_chromatic_params.csv"
    rows = list(csv.DictReader(src.open()))
    params = cn.tse_parameters()
    for row in rows:
        c, level = cn._CHROMATIC.index(row["category"]), int(row["level"]) - 1
        assert params.present[c, level] == (row["category_present_at_level"] == "1")
        if params.present[c, level]:
            assert params.chromatic[c, level, 0] == float(row["t_x"])
            assert params.chromatic[c, level, 9] == float(row["phi_e_rad"])


@pytest.mark.parametrize("term", cn.COLOUR_NAMES)
def test_focal_colours_get_their_name(term):
    srgb = np.array(FOCAL_SRGB8[term]) / 255.0
    assert str(cn.colour_names(srgb)) == term
    memberships = cn.colour_name_memberships(srgb)
    assert memberships[cn.COLOUR_NAMES.index(term)] > 0.5


def test_memberships_sum_to_one():
    axis = np.linspace(0.0, 1.0, 21)
    cube = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    raw = cn.colour_name_memberships(cube, normalise=False)
    assert np.all(raw >= 0.0)
    total = raw.sum(axis=1)
    assert total.min() >= 1.0 - 1e-9 and total.max() <= RAW_SUM_MAX
    assert np.mean(np.abs(total - 1.0) < 1e-2) > RAW_SUM_CLOSE_SHARE
    np.testing.assert_allclose(cn.colour_name_memberships(cube).sum(axis=1), 1.0, atol=1e-12)


def test_appendix_a_label_set():
    labels = cn.appendix_a_labels()
    assert labels.shape == (671, 11)  # 11 + 55 + 110 + 495 (Eq. A.1)
    nonzero = (labels > 0).sum(axis=1)
    assert [int((nonzero == k).sum()) for k in (1, 2, 3)] == [11, 55 + 110, 495]
    np.testing.assert_allclose(labels.sum(axis=1), 1.0)
    assert len({tuple(r) for r in labels}) == 671
    # every label is its own nearest label; random vectors get the brute-force L1 nearest
    np.testing.assert_array_equal(cn.discretise_memberships(labels), np.arange(671))
    rng = np.random.default_rng(3)
    p = rng.dirichlet(np.full(11, 0.3), size=200)
    brute = np.abs(p[:, None, :] - labels[None]).sum(axis=2)
    chosen = cn.discretise_memberships(p)
    np.testing.assert_allclose(brute[np.arange(200), chosen], brute.min(axis=1), atol=1e-12)


def test_cached_colour_naming_tables_are_read_only():
    params = cn.tse_parameters()
    _frozen_arrays(params.chromatic, params.present, params.achromatic)
    _frozen_arrays(cn.appendix_a_labels(), cn.label_centroids())


def _frozen_arrays(*arrays: np.ndarray) -> None:
    for array in arrays:
        assert isinstance(array, np.ndarray)
        with pytest.raises(ValueError, match="read-only"):
            array.flat[0] = 0.5
