"""Colour-spread figures of the diversity report, against independent values."""

import math

import colour
import numpy as np
import pytest

from spectrinsic.gt_export.dataset.colour_spread import (
    hull_area,
    light_xy,
    material_chroma,
    spread_summary,
)


def test_hull_area_of_known_polygons():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [0.2, 0.7]])
    assert hull_area(square) == pytest.approx(1.0)
    assert hull_area(np.array([[0, 0], [2, 0], [0, 3]])) == pytest.approx(3.0)
    assert hull_area(np.array([[0, 0], [1, 1]])) == 0.0


def test_material_chroma_matches_colour_science_and_grows_with_munsell_chroma():
    # independent: colour-science's own sd_to_XYZ (D65, 1931 2 deg) and XYZ_to_Lab
    from spectrinsic.spectra import get_spectrum

    spd = get_spectrum("munsell:5R 4/14")
    sd = colour.SpectralDistribution(dict(zip(spd.wavelengths, spd.values, strict=True)))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    d65 = colour.SDS_ILLUMINANTS["D65"]
    xyz = (
        colour.sd_to_XYZ(
            sd.copy().align(cmfs.shape, extrapolator_kwargs={"method": "Constant"}), cmfs, d65
        )
        / 100
    )
    lab = colour.XYZ_to_Lab(
        xyz, colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    )
    assert material_chroma("munsell:5R 4/14") == pytest.approx(math.hypot(lab[1], lab[2]), rel=0.02)
    assert material_chroma("flat:0.5") == pytest.approx(0.0, abs=1e-6)
    chromas = [material_chroma(f"munsell:5R 4/{c}") for c in (2, 6, 10, 14)]
    assert chromas == sorted(chromas) and chromas[0] > 0.5


def test_spread_summary_of_a_two_sample_set():
    red, blue = light_xy("led:630/20"), light_xy("led:460/20")
    d65 = light_xy("cie:D65")
    samples = [
        {
            "lights": [red, blue],
            "materials": ["flat:0.5"],
            "patterned": 1,
            "objects": 2,
            "coverage": 0.5,
        },
        {
            "lights": [d65],
            "materials": ["munsell:5R 4/14"],
            "patterned": 0,
            "objects": 2,
            "coverage": 0.1,
        },
    ]
    s = spread_summary(samples)
    assert s["xy_hull_area"] == pytest.approx(hull_area(np.array([red, blue, d65])))
    assert s["pair_distance_min"] == pytest.approx(math.dist(red, blue))
    assert s["d65_distance_max"] == pytest.approx(
        max(math.dist(red, (0.31271, 0.32902)), math.dist(blue, (0.31271, 0.32902)))
    )
    # D65 is not "coloured"; the blue LED is far below the locus, the red one on its extension
    assert s["tinted_fraction"] == pytest.approx(0.5)
    assert s["patterned_fraction"] == pytest.approx(0.25) and s["framed_fraction"] == pytest.approx(
        0.5
    )


def test_a_sample_record_counts_face_and_per_pixel_textures_as_textured():
    from types import SimpleNamespace

    from spectrinsic.gt_export.dataset.diversity import spread_record

    extra = {"patterns": ["texture", "pixel-texture", "stripes"], "n_objects": 4}
    meta = SimpleNamespace(lights=[], materials={}, scene_metadata=extra)
    record = spread_record(meta)  # type: ignore[arg-type]
    assert record["textured"] == 2 and record["patterned"] == 3 and record["objects"] == 4
