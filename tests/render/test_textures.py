"""Spectral textures rendered per band with exact ground truth (issue 22, item 2).

Independent values: the texel spectrum of each pixel is found by geometry alone (the pixel's
footprint on a quad facing the camera, mapped to uv by hand, never through the renderer), and
integrated under D65 with colour-science's ``sd_to_XYZ`` and ``XYZ_to_RGB``.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from spectrinsic.errors import RenderError
from spectrinsic.gt_export.layers import compute_ground_truth
from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene
from spectrinsic.scenes.textures import Texture, basis_name, make_texture
from spectrinsic.scenes.validate import validate_scene
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as WL
from spectrinsic.spectra import get_spectrum
from spectrinsic.spectra.working_space import DEFAULT_WORKING_SPACE, WORKING_SPACES

#: Done-when of issue 22: textured reflectance equals the texel spectra integrated independently.
EXACT = 1e-4
#: Spectral (wavelength-sampled) against 31-band image, per texel mean of 16+ pixels at 32 spp:
#: Monte Carlo colour noise of hero-wavelength sampling plus band integration.
SPECTRAL_RTOL = 0.03
#: Band integration (31 box bands of 10 nm) against 1 nm integration.
BAND_RTOL = 5e-3
BASIS = ("munsell:5R 4/14", "munsell:5G 6/8", "munsell:7.5PB 3/10")
SIZE, TEXELS, FOV = 32, 8, 30.0
DISTANCE = 3.0


def _scene(texture: Texture | None) -> Scene:
    """A 2 × 2 quad in z = 0 (uv = ((x + 1) / 2, (y + 1) / 2) by :func:`box_uv`) seen head-on
    from z = 3, lit by a distant D65 light along -z; the quad fills the frame."""
    mats = tuple(Material(basis_name("wood", b), s) for b, s in enumerate(BASIS))
    v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0.0]])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    return Scene(
        "texquad",
        (Mesh("quad", v, f, np.zeros(2, np.int64), 0, texture=texture),),
        mats,
        (Light("directional", "cie:D65", 3.0, direction=(0.0, 0.0, -1.0)),),
        Camera((0, 0, DISTANCE), (0, 0, 0), (0, 1, 0), FOV, SIZE, SIZE),
    )


def _texel_of_pixels() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Row, column of the texel under each pixel, and whether the pixel's whole footprint lies
    in that one texel (pixel row 0 at the top, +y; column 0 at the left, -x)."""
    half = DISTANCE * math.tan(math.radians(FOV / 2))
    edges = np.linspace(-half, half, SIZE + 1)
    texel = np.floor((edges + 1.0) / 2.0 * TEXELS)
    col_lo, col_hi = texel[:-1], texel[1:]
    row_lo, row_hi = texel[::-1][:-1], texel[::-1][1:]  # rows run down from +y
    inside = (row_lo == row_hi)[:, None] & (col_lo == col_hi)[None, :]
    rows = np.broadcast_to(np.minimum(row_lo, row_hi)[:, None], (SIZE, SIZE))
    cols = np.broadcast_to(col_lo[None, :], (SIZE, SIZE))
    return rows.astype(int), cols.astype(int), inside


def _rgb_colour_science(spectrum: np.ndarray) -> np.ndarray:
    """Linear RGB of the layers' default working space (ACEScg, no chromatic adaptation) of a
    reflectance under D65, white Y = 1, integrated by colour-science."""
    import colour

    shape = colour.SpectralShape(float(WL[0]), float(WL[-1]), 1.0)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    sd = colour.SpectralDistribution(dict(zip(WL.tolist(), spectrum.tolist(), strict=True)))
    xyz = colour.sd_to_XYZ(sd, cmfs, d65, method="Integration") / 100.0
    space = WORKING_SPACES[DEFAULT_WORKING_SPACE]
    return np.asarray(colour.XYZ_to_RGB(xyz, space, apply_cctf_encoding=False))


@pytest.fixture(scope="module")
def textured():
    texture = make_texture("wood", (0, 1, 2), "noise", TEXELS, seed=2)
    scene = _scene(texture)
    validate_scene(scene)
    result = render_scene(
        scene, RenderSettings(32, max_depth=2, modes=("spectral", "bands31")), seed=1
    )
    return scene, texture, result, compute_ground_truth(scene, result)


def test_textured_reflectance_equals_the_texel_spectra_integrated_by_colour_science(textured):
    scene, texture, _, gt = textured
    rows, cols, inside = _texel_of_pixels()
    assert inside.sum() >= 400  # most pixels lie inside one texel (5 × 5 pixels per texel)
    rho = np.stack([get_spectrum(s).on(WL) for s in BASIS])
    expected = np.array(
        [
            _rgb_colour_science(texture.weights[r, c] @ rho)
            for r, c in zip(rows[inside], cols[inside])
        ]
    )
    got = gt.layers["reflectance"].data[inside]
    assert np.abs(got - expected).max() < EXACT
    # the texture varies: far more distinct reflectances than basis spectra
    assert len(np.unique(np.round(got, 4), axis=0)) > 10


def test_spectral_image_agrees_with_the_band_image_texel_by_texel(textured):
    _, _, result, _ = textured
    rows, cols, inside = _texel_of_pixels()
    spectral, bands = result.images["spectral"], result.images["bands31"]
    keys = rows * TEXELS + cols
    for key in np.unique(keys[inside]):
        sel = inside & (keys == key)
        a, b = spectral[sel].mean(axis=0), bands[sel].mean(axis=0)
        np.testing.assert_allclose(a, b, rtol=SPECTRAL_RTOL, atol=SPECTRAL_RTOL * a.max())


def test_image_equals_reflectance_times_shading_on_a_textured_plane(textured):
    """Head-on distant light, direct only: no residual, and shading is flat across texels."""
    _, _, _, gt = textured
    image, refl = gt.layers["image"].data, gt.layers["reflectance"].data
    shading, residual = gt.layers["shading"].data, gt.layers["residual"].data
    np.testing.assert_allclose(refl * shading + residual, image, rtol=1e-5, atol=1e-6)
    assert np.abs(residual).max() < BAND_RTOL * np.abs(image).max()
    _, _, inside = _texel_of_pixels()
    flat = shading[inside]
    assert np.abs(flat - np.median(flat, axis=0)).max() < BAND_RTOL * np.median(flat)


def test_a_one_basis_texture_renders_as_its_flat_material():
    """Weights all on basis 0: the band transport equals the untextured mesh's (same paths)."""
    weights = np.zeros((4, 4, 3))
    weights[..., 0] = 1.0
    settings = RenderSettings(4, max_depth=2, modes=("rgb3",), aovs=True)
    flat = render_scene(_scene(None), settings, seed=5)
    tex = render_scene(_scene(Texture("wood", (0, 1, 2), weights)), settings, seed=5)
    np.testing.assert_allclose(tex.images["rgb3"], flat.images["rgb3"], rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(tex.aovs["coverage"], flat.aovs["coverage"], atol=1e-6)


def test_the_passes_integrator_refuses_textures_in_one_line():
    scene = _scene(make_texture("wood", (0, 1, 2), "rings", 4, seed=0))
    with pytest.raises(RenderError) as err:
        render_scene(scene, RenderSettings(1, modes=("rgb3",), integrator="passes"), seed=0)
    assert "spectral textures" in str(err.value) and "\n" not in str(err.value)
    plain = replace(scene, meshes=(replace(scene.meshes[0], texture=None),))
    render_scene(plain, RenderSettings(1, modes=("rgb3",), integrator="passes"), seed=0)


def test_a_spectral_only_render_takes_the_textured_coverage_from_one_traversal(textured):
    """No diagonal mode: the first-hit maps still come from a band-path traversal (the coverage
    passes cannot split a texel), so the reflectance is the same exact one."""
    scene, _, _, gt = textured
    result = render_scene(scene, RenderSettings(2, max_depth=2, modes=("spectral",)), seed=3)
    alone = compute_ground_truth(scene, result).layers["reflectance"].data
    _, _, inside = _texel_of_pixels()
    np.testing.assert_allclose(alone[inside], gt.layers["reflectance"].data[inside], atol=1e-6)
