"""Glass and mirrors (issue 42, item 1): a Cornell-like XML box with a glass gem and a perfect
mirror against Mitsuba's own spectral ``path`` render of the same file, the ground truth on
glass (reflectance 0, transmissive coverage 1, the identity on every pixel), and a thin pane
whose transmission is the closed form of Mitsuba's ``thindielectric``.

Independent values: Mitsuba's own spectral path tracer (``mi.load_file`` of the file the test
writes, its film made CIE XYZ), the Fresnel equations integrated here, and the same scene
without the pane.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.cli import main
from spectrinsic.errors import SceneError
from spectrinsic.gt_export.layers import compute_ground_truth
from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene

from ._reference import SMOOTH_GLASS, assert_matches_mitsuba, box_xml, icosahedron_obj

#: The shared box (:func:`box_xml`) with a red left wall, a 1.2-wide mirror centred on the back
#: wall and a BK7 glass gem (the icosahedron) on the floor.
XML = box_xml(
    bsdfs="""  <bsdf type="diffuse" id="red">
    <spectrum name="reflectance" value="360:0.05, 560:0.05, 600:0.6, 830:0.6"/></bsdf>
  <bsdf type="diffuse" id="green">
    <spectrum name="reflectance" value="360:0.1, 480:0.1, 530:0.5, 580:0.1, 830:0.1"/></bsdf>""",
    floor="white",
    left="red",
    mirror=("0.6", "0 0.99 1"),
    inside="""  <shape type="obj" id="gem">
    <string name="filename" value="gem.obj"/><boolean name="face_normals" value="true"/>
    <ref id="glass"/>
    <transform name="to_world"><scale value="0.45"/><translate value="0 -0.2 0.6"/></transform>
  </shape>""",
)


@pytest.fixture
def glass_box(tmp_path):
    (tmp_path / "gem.obj").write_text(icosahedron_obj())
    (tmp_path / "box.xml").write_text(XML)
    return tmp_path / "box.xml"


#: A rough glass in the place of :data:`SMOOTH_GLASS`.
ROUGH_GLASS = (
    '<bsdf type="roughdielectric" id="glass"><float name="alpha" value="0.2"/>'
    '<string name="distribution" value="ggx"/></bsdf>'
)


@pytest.mark.parametrize("glass", [SMOOTH_GLASS, ROUGH_GLASS], ids=["smooth", "rough"])
def test_a_glass_gem_and_a_mirror_match_mitsubas_own_spectral_path_render(glass_box, glass):
    """Per 8 × 8 block and XYZ channel, the band path's image equals Mitsuba's spectral ``path``
    of the same file within t standard errors of the difference, measured from the spread of
    SEEDS independent seeds of each (t: Student's quantile for a family-wise false alarm of
    FALSE_ALARM over the 48 comparisons, about 6); and the ground truth on the gem is
    reflectance 0, transmissive coverage 1, with the identity to float precision on every pixel.

    Measured (16 seeds, 128 spp ours, 512 spp Mitsuba): block ratios 0.98–1.02, |z| ≤ 2.9,
    standard errors 0.3–1.3 % of the block means; rough (α 0.2) and thin glass alike (64/256
    spp: |z| ≤ 3.0, ratios 0.97–1.02)."""
    glass_box.write_text(XML.replace(SMOOTH_GLASS, glass))
    scene = load_mitsuba_xml(glass_box)
    kinds = {m.name: m.kind for m in scene.materials}
    assert kinds["glass"] == "dielectric" and kinds["mirror"] == "conductor"
    results = assert_matches_mitsuba(scene, glass_box, 16, 64)

    gt = compute_ground_truth(scene, results[0])
    layers = {k: v.data.astype(np.float64) for k, v in gt.layers.items()}
    glass = layers["transmissive"] == 1.0
    mirror = layers["metallic"] == 1.0
    assert glass.sum() > 40 and mirror.sum() > 40
    assert np.all(layers["reflectance"][glass | mirror] == 0.0)
    # all the gem shows, the box seen through it, is specular; its shading the white surface's
    np.testing.assert_allclose(layers["specular"][glass], layers["image"][glass], atol=1e-4)
    assert layers["specular"][glass].mean() > 0.1 * layers["image"].mean()
    assert np.all(layers["shading"][glass].sum(axis=-1) > 0)
    rebuilt = layers["reflectance"] * layers["shading"] + layers["specular"] + layers["residual"]
    np.testing.assert_allclose(rebuilt, layers["image"], rtol=1e-6, atol=1e-5)
    assert np.abs(layers["residual"][glass]).max() <= 1e-5 * layers["image"].max()


def test_the_glass_box_renders_with_full_ground_truth_that_passes_check(glass_box):
    out = glass_box.parent / "out"
    args = ["--ground-truth", "--preset", "preview", "--spp", "2", "--out", str(out)]
    assert main(["-q", "render", str(glass_box), *args]) == 0
    assert main(["-q", "check", str(out)]) == 0
    (meta,) = out.glob("*/meta.json")
    assert '"transmissive"' in meta.read_text()


def _thin_fresnel(cos_i: float, eta: float) -> float:
    """Reflectance of a thin pane with its inter-reflections, ``R' = 2R / (1 + R)`` for the
    unpolarised single-interface Fresnel reflectance R (the sum of the geometric series Mitsuba's
    ``thindielectric`` uses)."""
    sin_t2 = (1 - cos_i**2) / eta**2
    cos_t = np.sqrt(1 - sin_t2)
    r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    r = 0.5 * (r_s**2 + r_p**2)
    return 2 * r / (1 + r)


def _pane_scene(pane: bool) -> Scene:
    """A grey wall at y = 1 lit by a point light in front of it; the camera at y = -3 looks at
    it through a thin glass pane at y = 0 turned 40° about z (its mirror image of the camera's
    rays goes to the empty side)."""
    wall = np.array([[-3.0, 1, -3], [3, 1, -3], [3, 1, 3], [-3, 1, 3]])
    c, s = np.cos(np.radians(40)), np.sin(np.radians(40))
    glass = np.array([[-1.5 * c, -1.5 * s, -1], [1.5 * c, 1.5 * s, -1],
                      [1.5 * c, 1.5 * s, 1], [-1.5 * c, -1.5 * s, 1]])  # fmt: skip
    quad = np.array([[0, 1, 2], [0, 2, 3]])
    meshes = [Mesh("wall", wall, quad, np.zeros(2, np.int64), 0)]
    if pane:
        meshes.append(Mesh("pane", glass, quad, np.ones(2, np.int64), 1))
    camera = Camera(
        origin=(0, -3, 0), target=(0, 0, 0), up=(0, 0, 1), fov_deg=6, width=16, height=16
    )
    return Scene(
        "pane",
        tuple(meshes),
        (Material("grey", "flat:0.5"), Material("pane", "flat:0", kind="thindielectric")),
        (Light("point", "cie:D65", 1.0, position=(0.0, 0.5, 0.0), name="bulb"),),
        camera,
    )


def test_a_thin_pane_shows_the_wall_behind_it_in_specular_at_its_transmittance():
    """The wall through the pane is the pane's ``specular`` layer (reflectance 0 there) and is
    the wall seen directly times ``1 − R'(40°)`` (about (1 − R)²), within Monte Carlo error
    of the pane's reflect-or-transmit choice. Depth 3 keeps light bounced between pane and
    wall out of both renders."""
    settings = RenderSettings(64, modes=("bands31",), max_depth=3)
    seen = {}
    for pane in (False, True):
        scene = _pane_scene(pane)
        gt = compute_ground_truth(scene, render_scene(scene, settings, seed=5))
        seen[pane] = {k: v.data.astype(np.float64) for k, v in gt.layers.items()}
    through = seen[True]
    assert np.all(through["transmissive"] == 1.0) and np.all(through["reflectance"] == 0.0)
    np.testing.assert_allclose(through["specular"], through["image"], rtol=1e-5, atol=1e-7)
    ratio = through["specular"].mean(axis=(0, 1)) / seen[False]["image"].mean(axis=(0, 1))
    expected = 1 - _thin_fresnel(np.cos(np.radians(40)), 1.5)
    assert 0.85 < expected < 0.95
    np.testing.assert_allclose(ratio, expected, rtol=0.01)


@pytest.mark.parametrize(
    ("bsdf", "expected"),
    [
        ('<bsdf type="roughdielectric" id="glass"/>', "distribution beckmann (the default)"),
        (  # a reflection tint is read (test_tinted_glass.py), but only as a fraction
            '<bsdf type="dielectric" id="glass"><float name="specular_reflectance" '
            'value="1.5"/></bsdf>',
            "specular_reflectance",
        ),
        (
            '<bsdf type="thindielectric" id="glass"><string name="int_ior" value="glass"/></bsdf>',
            "int_ior 'glass'",
        ),
        (  # a plastic's specular_reflectance scales its coat's reflection: refused as a tint
            '<bsdf type="plastic" id="glass">'
            '<float name="specular_reflectance" value="0.5"/></bsdf>',
            "specular_reflectance 0.5",
        ),
    ],
)
def test_beckmann_tinted_or_unknown_glass_is_refused_in_one_line(glass_box, capsys, bsdf, expected):
    bad = glass_box.with_name("bad.xml")
    bad.write_text(XML.replace(SMOOTH_GLASS, bsdf))
    with pytest.raises(SceneError, match="glass"):
        load_mitsuba_xml(bad)
    assert main(["render", str(bad), "--out", str(glass_box.parent / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err, err
    assert not (glass_box.parent / "o").exists()


def test_named_and_numeric_iors_and_a_rough_ggx_glass_are_read_exactly(glass_box):
    """bk7 over air is Mitsuba's 1.5046 / 1.000277; a rough GGX glass keeps its alpha."""
    scene = load_mitsuba_xml(glass_box)
    (glass,) = [m for m in scene.materials if m.name == "glass"]
    assert glass.ior == pytest.approx(1.5046 / 1.000277, rel=1e-6)
    rough = (
        '<bsdf type="roughdielectric" id="glass"><float name="alpha" value="0.2"/>'
        '<string name="distribution" value="ggx"/><float name="int_ior" value="1.33"/>'
        '<float name="ext_ior" value="1"/></bsdf>'
    )
    path = glass_box.with_name("rough.xml")
    path.write_text(XML.replace(SMOOTH_GLASS, rough))
    (glass,) = [m for m in load_mitsuba_xml(path).materials if m.name == "glass"]
    assert (glass.kind, glass.roughness, glass.ior) == ("dielectric", 0.2, pytest.approx(1.33))


def test_the_passes_integrator_refuses_glass_in_one_line_before_any_work(glass_box, capsys):
    out = glass_box.parent / "passes"
    args = ["--ground-truth", "--integrator", "passes", "--out", str(out)]
    assert main(["render", str(glass_box), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "glass materials" in err and "passes" in err
    assert not out.exists()


def test_approximate_takes_a_tinted_plastic_coat_as_untinted_and_says_so(glass_box):
    """Tinted glass and conductors are exact (``test_tinted_glass.py``); a tinted plastic
    coat is not."""
    tinted = (
        '<bsdf type="plastic" id="glass">'
        '<rgb name="specular_reflectance" value="0.5, 0.9, 0.5"/></bsdf>'
    )
    path = glass_box.with_name("tinted.xml")
    path.write_text(XML.replace(SMOOTH_GLASS, tinted))
    scene = load_mitsuba_xml(path, approximate=True)
    (glass,) = [m for m in scene.materials if m.name == "glass"]
    assert glass.kind == "plastic"
    (said,) = scene.metadata["approximated"]
    assert "specular_reflectance [0.5, 0.9, 0.5] taken as 1" in said


def test_a_thin_pane_stays_the_first_hit_in_a_scene_with_masks(glass_box):
    """Mitsuba's ``thindielectric`` transmits with a null event, as a mask's hole does; with a
    masked floor in the scene, the thin gem's pixels still have the gem as first hit (all in
    specular, reflectance 0), not the box behind it."""
    thin = '<bsdf type="thindielectric" id="glass"/>'
    masked = (
        '<bsdf type="mask" id="holey"><float name="opacity" value="0.5"/><ref id="white"/></bsdf>'
    )
    text = XML.replace(SMOOTH_GLASS, thin).replace(
        '<shape type="rectangle" id="floor"><ref id="white"/>',
        masked + '<shape type="rectangle" id="floor"><ref id="holey"/>',
    )
    glass_box.write_text(text)
    scene = load_mitsuba_xml(glass_box)
    assert any(m.maps is not None and m.maps.masked for m in scene.meshes)
    result = render_scene(scene, RenderSettings(8, modes=("bands31",), max_depth=4), seed=2)
    layers = {
        k: v.data.astype(np.float64) for k, v in compute_ground_truth(scene, result).layers.items()
    }
    glass = layers["transmissive"] == 1.0
    assert glass.sum() > 40
    assert np.all(layers["reflectance"][glass] == 0.0)
    np.testing.assert_allclose(layers["specular"][glass], layers["image"][glass], atol=1e-4)
