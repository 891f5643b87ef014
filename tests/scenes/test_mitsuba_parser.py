"""Mitsuba XML through Mitsuba's own parser (issue 41 item 1, issue 44 causes 3-6 and 11): every
point, colour, spectrum and reference form, old-version files and their fixes, sphere area
lights, and one-line refusals of what has no exact ground truth."""

from __future__ import annotations

import os

import numpy as np
import pytest
from PIL import Image

from spectrinsic.cli import main
from spectrinsic.errors import SceneError
from spectrinsic.scenes.meshes import MAX_FACES
from spectrinsic.scenes.mitsuba_spectra import planck_radiance
from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml, render_hints_line
from spectrinsic.scenes.reading_notes import reading_notes
from spectrinsic.spectra.user_spectra import inline_name

FLOOR = '<shape type="rectangle" id="floor"><transform name="to_world"><scale value="3"/></transform>{bsdf}</shape>'
CAMERA = """<sensor type="perspective"><float name="fov" value="50"/>
  <transform name="to_world"><lookat origin="0, -3, 1" target="0, 0, 0" up="0, 0, 1"/></transform>
  <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="$h"/></film>
</sensor>"""
LAMP = '<emitter type="point"><point name="position" x="0" y="0" z="2"/><rgb name="intensity" value="5"/></emitter>'


def _scene(body: str, *, version: str = "3.0.0", bsdf: str = "", h: str = "6") -> str:
    return (
        f'<scene version="{version}"><default name="spp" value="4"/><default name="h" value="{h}"/>'
        f"{FLOOR.format(bsdf=bsdf)}{body}{CAMERA}</scene>"
    )


def _write(folder, text, name="scene.xml"):
    path = folder / name
    path.write_text(text)
    return path


def test_point_forms_rgb_value_5_and_params_are_read(tmp_path):
    scene = load_mitsuba_xml(_write(tmp_path, _scene(LAMP)))
    (lamp,) = scene.lights
    assert (lamp.kind, lamp.spectrum, lamp.power, lamp.position) == (
        "point",
        "cie:D65",
        5.0,
        (0.0, 0.0, 2.0),
    )
    assert (scene.camera.width, scene.camera.height) == (8, 6)  # $h from its <default>
    assert scene.metadata["render_hints"] == {"spp": 4}
    ball = '<shape type="sphere"><point name="center" x="0.5" y="-0.5" z="0.4"/><float name="radius" value="0.25"/></shape>'
    scene = load_mitsuba_xml(_write(tmp_path, _scene(LAMP + ball)))
    ball_mesh = scene.meshes[1]
    np.testing.assert_allclose(ball_mesh.vertices.mean(0), [0.5, -0.5, 0.4], atol=1e-12)
    radii = np.linalg.norm(ball_mesh.vertices - [0.5, -0.5, 0.4], axis=1)
    np.testing.assert_allclose(radii, 0.25, rtol=1e-12)


def test_blackbody_keeps_mitsubas_absolute_planck_radiance(tmp_path):
    import colour

    lamp = (
        '<shape type="rectangle"><transform name="to_world"><translate z="2"/></transform>'
        '<boolean name="flip_normals" value="true"/><emitter type="area">'
        '<spectrum type="blackbody" name="radiance"><float name="temperature" value="2700"/>'
        "</spectrum></emitter></shape>"
    )
    (light,) = load_mitsuba_xml(_write(tmp_path, _scene(lamp))).lights
    assert (light.kind, light.spectrum, light.direction) == ("area", "planck:2700K", (0, 0, -1))
    # Planck's law from colour-science (W sr-1 m-2 m-1), per nm, weighted by ybar; colour
    # takes CODATA 2018 constants, Mitsuba older ones: 2.4e-4 apart
    wl = np.arange(360, 831)
    b = colour.colorimetry.planck_law(wl * 1e-9, 2700) * 1e-9
    ybar = (
        colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
        .copy()
        .align(colour.SpectralShape(360, 830, 1))
        .values[:, 1]
    )
    np.testing.assert_allclose(planck_radiance(wl, 2700), b, rtol=5e-4)
    assert light.power == pytest.approx(float((b * ybar).sum() / ybar.sum()), rel=5e-4)


def test_irregular_csv_and_spd_spectra_and_their_files_are_recorded(tmp_path):
    (tmp_path / "paints.csv").write_text(
        "wavelength,red [1]\n"
        + "".join(f"{w},{0.1 + 0.5 * (w > 580)}\n" for w in range(380, 781, 10))
    )
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "inc.xml").write_text(
        '<scene version="3.0.0"><bsdf type="diffuse" id="irr"><spectrum type="irregular" '
        'name="reflectance"><string name="wavelengths" value="400, 550, 700"/>'
        '<string name="values" value="0.2, 0.5, 0.3"/></spectrum></bsdf></scene>'
    )
    body = (
        LAMP + '<include filename="sub/inc.xml"/>'
        '<bsdf type="diffuse" id="paint"><string name="reflectance" value="csv:paints.csv#red"/></bsdf>'
        '<shape type="cube" id="box"><ref id="paint"/><transform name="to_world">'
        '<scale value="0.2"/><translate z="0.2"/></transform></shape>'
        '<shape type="disk" id="mat"><ref id="irr"/><transform name="to_world"><translate z="0.01"/></transform></shape>'
    )
    scene = load_mitsuba_xml(_write(tmp_path, _scene(body)))
    by_name = {m.name: m.spectrum for m in scene.materials}
    assert by_name["irr"] == inline_name([400, 550, 700], [0.2, 0.5, 0.3], "reflectance")
    assert by_name["paint"].startswith("csv:") and by_name["paint"].endswith("paints.csv#red")
    files = {f["path"]: f["role"] for f in scene.metadata["files"]}
    assert files == {"sub/inc.xml": "include", "paints.csv": "csv"}
    assert all(len(f["sha256"]) == 64 for f in scene.metadata["files"])


def test_refs_instances_and_every_built_in_shape_become_triangles(tmp_path):
    body = (
        LAMP + '<bsdf type="twosided" id="grey"><bsdf type="diffuse">'
        '<float name="reflectance" value="0.3"/></bsdf></bsdf>'
        '<shape type="shapegroup" id="post"><shape type="cylinder"><float name="radius" value="0.05"/>'
        '<point name="p0" value="0, 0, 0"/><point name="p1" x="0" y="0" z="0.5"/><ref id="grey"/></shape></shape>'
        '<shape type="instance"><ref id="post"/><transform name="to_world"><translate x="-1"/></transform></shape>'
        '<shape type="instance"><ref id="post"/><transform name="to_world"><translate x="1"/></transform></shape>'
    )
    scene = load_mitsuba_xml(_write(tmp_path, _scene(body)))
    posts = [m for m in scene.meshes if m.name != "floor"]
    assert len(posts) == 2 and scene.materials[posts[0].face_materials[0]].spectrum == "flat:0.3"
    xs = sorted(float(m.vertices[:, 0].mean()) for m in posts)
    np.testing.assert_allclose(xs, [-1, 1], atol=1e-12)
    assert [m.vertices[:, 2].max() for m in posts] == pytest.approx([0.5, 0.5])


OLD = """<?xml version="1.0"?>
<scene version="0.5.0">
  <integrator type="path"><integer name="maxDepth" value="3"/></integrator>
  <bsdf type="roughplastic" id="p"><rgb name="diffuseReflectance" value="0.5, 0.2, 0.1"/>
    <float name="intIOR" value="1.6"/><float name="extEta" value="1.0"/>
    <string name="distribution" value="ggx"/></bsdf>
  <bsdf type="diffuse" id="tex"><texture type="bitmap" name="reflectance">
    <string name="filename" value="wood.png"/><string name="filterType" value="trilinear"/>
    <float name="gamma" value="2.2"/></texture></bsdf>
  <shape type="sphere"><point name="center" x="0" y="0" z="0.5"/><float name="radius" value="0.3"/><ref id="p"/></shape>
  <shape type="rectangle"><transform name="toWorld"><scale value="3"/></transform><ref id="tex"/></shape>
  <emitter type="point"><point name="position" x="0" y="0" z="2"/><spectrum name="intensity" value="3"/></emitter>
  <sensor type="perspective"><float name="fov" value="45"/><string name="fovAxis" value="y"/>
    <transform name="toWorld"><lookat origin="0 -3 1" target="0 0 0.5" up="0 0 1"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="2"/></sampler>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="6"/></film>
  </sensor>
</scene>"""


def test_a_mitsuba_05_file_loads_and_says_what_it_fixed(tmp_path, capsys):
    Image.fromarray(np.full((2, 2, 3), 128, np.uint8)).save(tmp_path / "wood.png")
    path = _write(tmp_path, OLD)
    with pytest.warns(UserWarning, match="bilinear filtering approximated by the nearest texel"):
        scene = load_mitsuba_xml(path)  # the bitmap on a diffuse is an exact image texture
    (wood,) = [m for m in scene.meshes if m.texture is not None]
    assert wood.texture.image.srgb and wood.texture.image.filter == "bilinear"
    plastic = next(m for m in scene.materials if m.kind == "plastic")
    assert plastic.ior == pytest.approx(1.6) and plastic.spectrum == "rgb:0.5,0.2,0.1"
    fixed = " | ".join(scene.metadata["fixed"])
    for phrase in (
        "ext_eta -> ext_ior",
        "filter_type trilinear -> bilinear",
        "gamma 2.2 -> raw=False",
    ):
        assert phrase in fixed
    assert scene.metadata["approximated"] == []
    assert scene.metadata["render_hints"] == {"max_depth": 3, "spp": 2}
    # fov 45 on the y axis of an 8x6 film is the x fov of tan(x/2) = tan(22.5°) 8/6
    assert scene.camera.fov_deg == pytest.approx(
        np.degrees(2 * np.arctan(np.tan(np.radians(22.5)) * 8 / 6))
    )
    notes = reading_notes(scene)
    assert all("\n" not in n for n in notes) and len(notes) == len(scene.metadata["fixed"])
    assert (
        render_hints_line(scene, None, 5)
        == "scene: spp 2 from the file, max depth 5 from the command line (the file says 3)"
    )


@pytest.mark.parametrize(
    ("body", "bsdf", "named"),
    [
        ('<emitter type="sunsky"/>', "", "<emitter type='sunsky'>"),
    ],
)
def test_what_has_no_exact_ground_truth_is_refused_or_approximated(
    tmp_path, monkeypatch, body, bsdf, named
):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))  # a sunsky's baked sky
    (tmp_path / "sky.exr").write_bytes(b"not read")
    box = '<shape type="cube" id="box"><transform name="to_world"><scale value="0.2"/><translate z="0.5"/></transform></shape>'
    path = _write(tmp_path, _scene(LAMP + box + body, bsdf=bsdf))
    with pytest.raises(SceneError) as info:
        load_mitsuba_xml(path)
    message = str(info.value)
    assert "\n" not in message and str(path) in message
    assert f"{named} has no exact ground truth yet" in message
    scene = load_mitsuba_xml(path, approximate=True)
    assert named in " ".join(scene.metadata["approximated"])
    assert [m.name for m in scene.meshes] == ["floor", "box"]


def test_an_unsupported_element_refuses_in_one_line_through_the_cli(tmp_path, capsys):
    path = _write(tmp_path, _scene(LAMP, bsdf='<bsdf type="roughdielectric" id="glass"/>'))
    assert main(["render", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "<bsdf type='roughdielectric' id='glass'>" in err
    assert not (tmp_path / "out").exists()
    yaml_scene = _write(tmp_path, "name: x\n", "x.yaml")
    assert main(["render", str(yaml_scene), "--approximate", "--out", str(tmp_path / "o")]) == 2
    assert "--approximate applies to Mitsuba XML scenes" in capsys.readouterr().err


def test_two_skies_merge_when_their_spectra_agree_and_are_refused_otherwise(tmp_path):
    sky = '<emitter type="constant"><rgb name="radiance" value="{v}"/></emitter>'
    scene = load_mitsuba_xml(_write(tmp_path, _scene(sky.format(v=0.5) + sky.format(v=0.25))))
    (merged,) = scene.lights
    assert (merged.kind, merged.spectrum, merged.power) == ("sky", "cie:D65", 0.75)
    other = '<emitter type="constant"><spectrum name="radiance" value="1"/></emitter>'
    with pytest.raises(SceneError, match="2 environment emitters with different spectra"):
        load_mitsuba_xml(_write(tmp_path, _scene(sky.format(v=0.5) + other)))


def test_a_film_of_height_0_is_refused_before_any_arithmetic(tmp_path):
    text = _scene(LAMP, h="0").replace(
        'value="50"/>', 'value="50"/><string name="fov_axis" value="y"/>'
    )
    with pytest.raises(SceneError, match="film height 0; expected a whole number from 1"):
        load_mitsuba_xml(_write(tmp_path, text))


def test_a_fifo_scene_or_mesh_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "pipe.xml"
    os.mkfifo(fifo)
    with pytest.raises(SceneError, match="is not a regular file"):
        load_mitsuba_xml(fifo)
    os.mkfifo(tmp_path / "pipe.obj")
    mesh = '<shape type="obj"><string name="filename" value="pipe.obj"/></shape>'
    with pytest.raises(SceneError, match="'.*pipe.obj' is not a regular file"):
        load_mitsuba_xml(_write(tmp_path, _scene(LAMP + mesh)))


def test_the_face_budget_counts_every_shape_and_reference_before_loading(tmp_path):
    ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    ply += f"property float z\nelement face {MAX_FACES // 4}\nproperty list uchar int vertex_indices\nend_header\n"
    (tmp_path / "big.ply").write_text(ply)  # its header declares the faces; no body is read
    group = '<shape type="shapegroup" id="g"><shape type="ply"><string name="filename" value="big.ply"/></shape></shape>'
    refs = "".join('<shape type="instance"><ref id="g"/></shape>' for _ in range(5))
    with pytest.raises(
        SceneError,
        match=r"6 shapes: .* brings the scene to 2\d\d,\d{3} faces; a scene holds at most 250,000 faces",
    ):
        load_mitsuba_xml(_write(tmp_path, _scene(LAMP + group + refs)))
    balls = "".join(
        f'<shape type="sphere"><point name="center" x="{i}" y="0" z="1"/></shape>'
        for i in range(300)
    )
    with pytest.raises(SceneError, match=r"301 shapes: .* brings the scene to 250,\d{3} faces"):
        load_mitsuba_xml(_write(tmp_path, _scene(LAMP + balls)))


@pytest.mark.render
def test_a_sphere_area_light_lights_the_floor_as_a_point_light_of_intensity_pi_r2_l(tmp_path):
    """A uniform sphere of radiance L and radius r that a receiver sees whole gives the
    irradiance of a point light of intensity π r² L at its centre (exact, not a far-field
    approximation), so direct-only renders of the two agree up to Monte Carlo noise."""
    from spectrinsic.render import RenderSettings, render_scene

    sphere = (
        '<shape type="sphere"><point name="center" x="0" y="0" z="1.5"/><float name="radius" '
        'value="0.3"/><emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>'
    )
    point = '<emitter type="point"><point name="position" x="0" y="0" z="1.5"/>'
    point += f'<rgb name="intensity" value="{np.pi * 0.09 * 2!r}"/></emitter>'
    camera = CAMERA.replace('origin="0, -3, 1"', 'origin="0, -0.4, 1"')  # the sphere out of view
    settings = RenderSettings(64, modes=("rgb3",), max_depth=2, aovs=False)
    images = []
    for light in (sphere, point):
        text = '<scene version="3.0.0"><default name="spp" value="4"/><default name="h" value="6"/>'
        text += f"{FLOOR.format(bsdf='')}{light}{camera}</scene>"
        scene = load_mitsuba_xml(_write(tmp_path, text))
        images.append(render_scene(scene, settings, seed=1).images["rgb3"][..., 1])
    assert scene.lights[0].kind == "point"
    lit, reference = images
    assert lit.mean() == pytest.approx(reference.mean(), rel=0.02)
    np.testing.assert_allclose(lit, reference, rtol=0.1)


@pytest.mark.render
def test_the_files_spp_and_depth_apply_unless_the_command_line_gives_them(tmp_path, capsys):
    import json

    text = _scene(LAMP).replace(
        '<scene version="3.0.0">',
        '<scene version="3.0.0"><integrator type="path"><integer name="max_depth" value="3"/></integrator>',
    )
    path, out = _write(tmp_path, text), tmp_path / "out"
    args = ["render", str(path), "--modes", "rgb3", "--no-aovs", "--spp", "2", "--out", str(out)]
    assert main(args) == 0
    meta = json.loads((out / "meta.json").read_text())
    assert (meta["spp"], meta["max_depth"]) == (2, 3)
    err = capsys.readouterr().err
    assert "spp 2 from the command line (the file says 4), max depth 3 from the file" in err


@pytest.mark.render
def test_approximate_is_said_and_recorded_in_the_samples_meta(tmp_path, capsys):
    import json

    bump = '<bsdf type="roughplastic" id="bumpy"/>'  # Beckmann, Mitsuba's default: as GGX
    path, out = _write(tmp_path, _scene(LAMP, bsdf=bump)), tmp_path / "gt"
    args = ["--preset", "preview", "--spp", "2", "--resolution", "8x6", "--out", str(out)]
    assert main(["render", str(path), "--ground-truth", "--approximate", *args]) == 0
    err = capsys.readouterr().err
    floor = "element 0 <shape type='rectangle' id='floor'>"
    assert f"approximated: {floor}: <bsdf type='roughplastic' id='bumpy'> distribution" in err
    assert (
        "spp 2 from the dataset's settings (preset 'preview' and options) (the file says 4)" in err
    )
    (meta_path,) = out.glob("**/meta.json")
    record = json.loads(meta_path.read_text())["scene_metadata"]
    assert record["approximate"] is True and "roughplastic" in record["approximated"][0]


def _serialized(meshes) -> bytes:
    """A Mitsuba ``.serialized`` file (format 4, single precision) holding *meshes*, written
    by hand from the format's description: per mesh a header and a zlib stream (flags, name,
    counts, positions, indices), then the table of mesh offsets and their count."""
    import struct
    import zlib

    out, offsets = b"", []
    for v, f in meshes:
        offsets.append(len(out))
        body = struct.pack("<I", 0x1000) + b"part\0" + struct.pack("<QQ", len(v), len(f))
        body += np.asarray(v, "<f4").tobytes() + np.asarray(f, "<u4").tobytes()
        out += struct.pack("<HH", 0x041C, 4) + zlib.compress(body)
    return out + b"".join(struct.pack("<Q", o) for o in offsets) + struct.pack("<I", len(meshes))


def test_a_serialized_mesh_is_read_by_index_and_counted_from_its_header(tmp_path):
    tri = ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    quad = ([[0, 0, 0.5], [0.4, 0, 0.5], [0.4, 0.4, 0.5], [0, 0.4, 0.5]], [[0, 1, 2], [0, 2, 3]])
    (tmp_path / "parts.serialized").write_bytes(_serialized([tri, quad]))
    shape = '<shape type="serialized" id="lid"><string name="filename" value="parts.serialized"/>'
    shape += '<integer name="shape_index" value="1"/></shape>'
    scene = load_mitsuba_xml(_write(tmp_path, _scene(LAMP + shape)))
    lid = {m.name: m for m in scene.meshes}["lid"]
    np.testing.assert_allclose(
        lid.vertices[lid.faces].reshape(-1, 3), np.asarray(quad[0])[[0, 1, 2, 0, 2, 3]]
    )
    with pytest.raises(SceneError, match="shape_index 2; the file holds 2 meshes"):
        load_mitsuba_xml(_write(tmp_path, _scene(LAMP + shape.replace('value="1"', 'value="2"'))))


def test_approximate_needs_an_xml_scene_among_the_dataset_files(tmp_path):
    import json

    from spectrinsic.errors import DatasetError
    from spectrinsic.pipeline.source_plan import files_source

    yaml_scene = _write(tmp_path, "name: x\n", "x.yaml")
    with pytest.raises(DatasetError, match="--approximate applies to Mitsuba XML scenes"):
        files_source([yaml_scene], approximate=True)
    spec = json.loads(files_source([_write(tmp_path, _scene(LAMP))], approximate=True))
    assert spec["approximate"] is True
    assert "approximate" not in json.loads(files_source([_write(tmp_path, _scene(LAMP))]))


def test_includes_are_inlined_with_bounds_and_stay_in_the_folder(tmp_path):
    (tmp_path / "loop.xml").write_text(
        '<scene version="3.0.0"><include filename="loop.xml"/></scene>'
    )
    with pytest.raises(SceneError, match="more than 256 includes or nested deeper than 8"):
        load_mitsuba_xml(_write(tmp_path, _scene(LAMP + '<include filename="loop.xml"/>')))
    (tmp_path / "old.xml").write_text('<scene version="0.5.0"/>')
    with pytest.raises(SceneError, match="version '0.5.0' differs from the scene's '3.0.0'"):
        load_mitsuba_xml(_write(tmp_path, _scene(LAMP + '<include filename="old.xml"/>')))
    os.mkfifo(tmp_path / "pipe_inc.xml")
    with pytest.raises(SceneError, match="pipe_inc.xml' is not a regular file"):
        load_mitsuba_xml(_write(tmp_path, _scene(LAMP + '<include filename="pipe_inc.xml"/>')))


def test_a_coloured_rgb_emission_is_a_light_of_that_linear_srgb_colour(tmp_path):
    import colour

    from spectrinsic.spectra import get_spectrum

    lamp = LAMP.replace(
        '<rgb name="intensity" value="5"/>', '<rgb name="intensity" value="10, 8, 6"/>'
    )
    (light,) = load_mitsuba_xml(_write(tmp_path, _scene(lamp))).lights
    wl = np.arange(360.0, 831.0)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy()
    cmf = cmfs.align(colour.SpectralShape(360, 830, 1)).values
    xyz = (get_spectrum(light.spectrum).on(wl)[:, None] * light.power * cmf).sum(0) / cmf[
        :, 1
    ].sum()
    rgb = colour.XYZ_to_RGB(xyz, colour.RGB_COLOURSPACES["sRGB"], apply_cctf_encoding=False)
    np.testing.assert_allclose(rgb, [10, 8, 6], rtol=1e-3)  # the basis's round trip under D65
    assert light.power == pytest.approx(xyz[1], rel=1e-4)  # power: the luminance (5 nm samples)


@pytest.mark.parametrize(
    ("element", "match"),
    [
        ('<shape type="sphere"><float name="radius" value="1e400"/></shape>', "its radius value"),
        ('<shape type="sphere"><float name="radius" value="inf"/></shape>', "its radius value"),
        (
            '<emitter type="directional"><vector name="direction" x="nan" y="0" z="-1"/>'
            '<rgb name="irradiance" value="1"/></emitter>',
            "its direction value",
        ),
        (
            '<emitter type="directional"><vector name="direction" value="0"/>'
            '<rgb name="irradiance" value="1"/></emitter>',
            r"direction \(0.0, 0.0, 0.0\) is a zero vector",
        ),
    ],
    ids=["radius-1e400", "radius-inf", "direction-nan", "direction-zero"],
)
def test_non_finite_values_and_zero_directions_are_refused_before_any_arithmetic(
    tmp_path, element, match
):
    """Found by the XML properties: an infinite sphere radius and a NaN or zero light direction
    reached numpy (a RuntimeWarning, then a NaN scene or a traceback-free but wrong error)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(SceneError, match=match):
            load_mitsuba_xml(_write(tmp_path, _scene(LAMP + element)))
