"""PNG previews: sRGB encoding, exposure, false colour."""

from __future__ import annotations

import numpy as np

from spectrinsic.gt_export.formats import png


def test_encoding_matches_the_srgb_cctf():
    import colour

    linear = np.linspace(0.0, 1.0, 11)[None, :, None].repeat(3, axis=-1)
    expected = np.round(colour.cctf_encoding(linear, function="sRGB") * 255)
    np.testing.assert_array_equal(png.encode_srgb8(linear), expected.astype(np.uint8))
    # IEC 61966-2-1: linear 0.0031308 is the breakpoint; 0.5 encodes to 0.7354
    assert png.encode_srgb8(np.full((1, 1, 3), 0.5))[0, 0, 0] == round(0.735357 * 255)


def test_exposure_maps_the_percentile_to_white():
    rng = np.random.default_rng(0)
    img = np.repeat(rng.random((50, 50, 1)) * 7.0, 3, axis=-1)  # greys: every channel = Y
    out = png.tone_map(img)
    level = np.percentile(img[..., 0], png.EXPOSURE_PERCENTILE)
    assert (out[img[..., 0] >= level] == 255).all()
    assert (out[img[..., 0] < 0.99 * level] < 255).all()
    assert 0.01 < (out[..., 0] == 255).mean() < 0.02  # about 1 % clip
    assert png.exposure(np.zeros((3, 3, 3))) == 1.0


def test_false_colour_uses_the_colormap_ends_and_blacks_out_the_mask():
    import matplotlib

    values = np.array([[0.0, 1.0], [0.5, 9.0]])
    mask = np.array([[True, True], [True, False]])
    out = png.false_colour(values, mask=mask, vmin=0.0, vmax=1.0)
    lut = np.round(np.asarray(matplotlib.colormaps["viridis"]([0.0, 1.0]))[:, :3] * 255)
    np.testing.assert_array_equal(out[0, 0], lut[0])
    np.testing.assert_array_equal(out[0, 1], lut[1])
    np.testing.assert_array_equal(out[1, 1], 0)


def test_ids_get_distinct_colours_and_background_black():
    ids = np.array([[-1, 0, 1, 2]])
    out = png.id_colours(ids)
    assert (out[0, 0] == 0).all()
    assert len({tuple(c) for c in out[0, 1:]}) == 3


def test_written_png_reads_back(tmp_path):
    from PIL import Image

    rgb8 = np.random.default_rng(2).integers(0, 256, (5, 6, 3), dtype=np.uint8)
    path = png.write_png(tmp_path / "x.png", rgb8)
    np.testing.assert_array_equal(np.asarray(Image.open(path)), rgb8)
