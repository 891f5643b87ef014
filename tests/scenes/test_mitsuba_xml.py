"""Mitsuba 3 XML scenes (issue 32): a Cornell box written as XML (its walls those of
``_cornell.py``) against the same box written as YAML by hand, full ground truth, and one-line
refusals."""

from __future__ import annotations

import hashlib
import json

import numpy as np
import pytest
import yaml

from spectrinsic.cli import main
from spectrinsic.errors import SceneError
from spectrinsic.scenes import load_scene
from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml

from ._cornell import box_walls

GREEN = {"wavelengths": [400, 500, 550, 600, 700], "values": [0.1, 0.4, 0.5, 0.2, 0.1]}
LAMP = {"wavelengths": [400, 450, 500, 550, 600, 650, 700], "values": [4, 5, 6, 6, 7, 7, 8]}


def _spectrum(d):
    return ", ".join(f"{w}:{v}" for w, v in zip(d["wavelengths"], d["values"]))


XML = f"""<scene version="3.0.0">
  <default name="res" value="12"/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.7, 0.7, 0.7"/></bsdf>
  <bsdf type="diffuse" id="red"><rgb name="reflectance" value="0.6, 0.05, 0.05"/></bsdf>
  <bsdf type="twosided" id="green"><bsdf type="diffuse">
    <spectrum name="reflectance" value="{_spectrum(GREEN)}"/></bsdf></bsdf>
{box_walls()}
  <shape type="obj" id="box"><string name="filename" value="box.obj"/><ref id="white"/>
    <transform name="to_world"><translate value="0.3 0.2 0"/></transform>
  </shape>
  <shape type="rectangle" id="lamp">
    <transform name="to_world">
      <scale value="0.25"/><rotate x="1" angle="180"/><translate value="0 0 1.99"/>
    </transform>
    <emitter type="area"><spectrum name="radiance" value="{_spectrum(LAMP)}"/></emitter>
  </shape>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, -3.5, 1" target="0, 0, 1" up="0, 0, 1"/></transform>
    <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
    <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/></film>
  </sensor>
</scene>
"""


def _yaml_box():
    """The same box by hand: each wall's corners worked out from its transform on paper."""
    import colour

    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wl, values = np.array(LAMP["wavelengths"]), np.array(LAMP["values"], float)
    y = np.interp(wl, ybar.wavelengths, ybar.values[:, 1])
    walls = {
        "floor": ([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], "white"),
        "ceiling": ([[-1, 1, 2], [1, 1, 2], [1, -1, 2], [-1, -1, 2]], "white"),
        "back": ([[-1, 1, 0], [1, 1, 0], [1, 1, 2], [-1, 1, 2]], "white"),
        "left": ([[-1, -1, 2], [-1, -1, 0], [-1, 1, 0], [-1, 1, 2]], "red"),
        "right": ([[1, -1, 0], [1, -1, 2], [1, 1, 2], [1, 1, 0]], "green"),
    }
    meshes = [
        {"name": n, "vertices": v, "faces": [[0, 1, 2], [0, 2, 3]], "material": m}
        for n, (v, m) in walls.items()
    ]
    meshes.append(
        {
            "name": "box",
            "file": "box.obj",
            "transform": {"translate": [0.3, 0.2, 0]},
            "material": "white",
        }
    )
    return {
        "name": "cornell",
        "materials": {"white": "rgb:0.7,0.7,0.7", "red": "rgb:0.6,0.05,0.05", "green": GREEN},
        "meshes": meshes,
        "lights": [
            {
                "kind": "area",
                "spectrum": LAMP,
                "power": float((values * y).sum() / y.sum()),
                "position": [0, 0, 1.99],
                "direction": [0, 0, -1],
                "size": [0.5, 0.5],
            }
        ],
        "camera": {
            "origin": [0, -3.5, 1],
            "target": [0, 0, 1],
            "up": [0, 0, 1],
            "fov_deg": 40,
            "width": 12,
            "height": 12,
        },
    }


@pytest.fixture
def cornell(tmp_path):
    box = "v -0.2 -0.2 0\nv 0.2 -0.2 0\nv 0.2 0.2 0\nv -0.2 0.2 0\n"
    box += "v -0.2 -0.2 0.5\nv 0.2 -0.2 0.5\nv 0.2 0.2 0.5\nv -0.2 0.2 0.5\n"
    box += "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
    box += "f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n"
    (tmp_path / "box.obj").write_text(box)
    (tmp_path / "cornell.xml").write_text(XML)
    (tmp_path / "cornell.yaml").write_text(yaml.safe_dump(_yaml_box()))
    return tmp_path


def _triangles(mesh):
    """The mesh's triangles as corner arrays, each rotated to start at its smallest corner
    (same orientation), sorted: equal for equal surfaces whatever the vertex order."""
    tris = np.round(np.asarray(mesh.vertices, float)[mesh.faces], 9)
    out = []
    for t in tris:
        k = min(range(3), key=lambda i: tuple(t[i]))
        out.append(np.roll(t, -k, axis=0).ravel())
    return np.array(sorted(map(tuple, out)))


def test_a_cornell_box_in_xml_equals_the_same_box_in_yaml(cornell):
    xml, ref = load_mitsuba_xml(cornell / "cornell.xml"), load_scene(cornell / "cornell.yaml")
    by_name = {m.name: m for m in ref.meshes}
    assert sorted(by_name) == sorted(m.name for m in xml.meshes)
    for mesh in xml.meshes:
        other = by_name[mesh.name]
        np.testing.assert_allclose(_triangles(mesh), _triangles(other), atol=1e-9)
        mine = xml.materials[int(mesh.face_materials[0])].spectrum
        assert mine == ref.materials[int(other.face_materials[0])].spectrum
    (a,), (b,) = xml.lights, ref.lights
    assert (a.kind, a.spectrum) == (b.kind, b.spectrum)
    for field in ("power", "position", "direction", "size"):
        np.testing.assert_allclose(getattr(a, field), getattr(b, field), rtol=1e-9, atol=1e-12)
    ca, cb = xml.camera, ref.camera
    np.testing.assert_allclose(ca.origin, cb.origin)
    np.testing.assert_allclose(np.subtract(ca.target, ca.origin), [0, 1, 0], atol=1e-12)
    assert (ca.fov_deg, ca.width, ca.height) == (cb.fov_deg, cb.width, cb.height)


def test_the_xml_box_renders_with_full_ground_truth(cornell):
    """The box with its green read from a .spd file (the same spectrum, test below), which the
    sample's meta.json records with its SHA-256 (issue 47)."""
    lines = "".join(f"{w} {v}\n" for w, v in zip(GREEN["wavelengths"], GREEN["values"]))
    (cornell / "green.spd").write_text(lines)
    spd = XML.replace(f'value="{_spectrum(GREEN)}"', 'filename="green.spd"')
    (cornell / "spd.xml").write_text(spd)
    out = cornell / "out"
    args = ["--ground-truth", "--preset", "preview", "--spp", "2", "--out", str(out)]
    assert main(["-q", "render", str(cornell / "spd.xml"), *args]) == 0
    assert main(["-q", "check", str(out)]) == 0
    (meta,) = [json.loads(p.read_text()) for p in out.glob("*/meta.json")]
    digest = hashlib.sha256((cornell / "green.spd").read_bytes()).hexdigest()
    assert [r["sha256"] for r in meta["spectrum_files"]] == [digest]


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        (
            '<bsdf type="diffuse" id="red">',
            '<bsdf type="roughdielectric" id="red">',
            "unsupported parameter 'reflectance' in <bsdf type='roughdielectric' id='red'>",
        ),
        (
            '<scene version="3.0.0">',
            '<scene version="3.0.0"><include filename="../x.xml"/>',
            "filename '../x.xml'; expected a path inside the scene's folder",
        ),
        (
            '<shape type="obj" id="box">',
            '<shape type="bsplinecurve" id="box">',
            "unsupported element <shape type='bsplinecurve' id='box'>",
        ),
        (
            'value="box.obj"',
            'value="../box.obj"',
            "filename '../box.obj'; expected a path inside the scene's folder",
        ),
        (
            '<scene version="3.0.0">',
            '<!DOCTYPE x [<!ENTITY a "b">]><scene version="3.0.0">',
            "DOCTYPE and ENTITY declarations",
        ),
    ],
)
def test_unsupported_xml_is_refused_in_one_line(cornell, capsys, old, new, expected):
    bad = cornell / "bad.xml"
    bad.write_text(XML.replace(old, new, 1))
    with pytest.raises(SceneError) as info:
        load_mitsuba_xml(bad)
    assert expected in str(info.value) and str(bad) in str(info.value)
    assert main(["render", str(bad), "--out", str(cornell / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err


def test_built_in_shapes_are_closed_outward_and_of_the_right_size():
    import trimesh

    from spectrinsic.scenes import mitsuba_parts as parts

    cube = trimesh.Trimesh(*parts.cube(), process=False)
    ball = trimesh.Trimesh(*parts.sphere(np.array([1.0, 2.0, 3.0]), 0.5), process=False)
    assert cube.is_watertight and cube.volume == pytest.approx(8.0)
    assert ball.is_watertight and ball.volume == pytest.approx(4 / 3 * np.pi * 0.125, rel=0.03)
    np.testing.assert_allclose(ball.vertices.mean(0), [1, 2, 3], atol=1e-9)
    disk = trimesh.Trimesh(*parts.disk(), process=False)
    assert disk.area == pytest.approx(np.pi, rel=0.01) and (disk.face_normals[:, 2] > 0).all()


def test_glossy_bsdfs_and_a_spot_become_glossy_materials_and_a_spot_light(cornell):
    glossy = (
        XML.replace(
            '<bsdf type="diffuse" id="red"><rgb name="reflectance" value="0.6, 0.05, 0.05"/></bsdf>',
            '<bsdf type="roughplastic" id="red"><rgb name="diffuse_reflectance" value="0.6, 0.05, 0.05"/>'
            '<float name="alpha" value="0.2"/><float name="int_ior" value="1.6"/>'
            '<string name="distribution" value="ggx"/></bsdf>',
        )
        .replace(
            '<bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.7, 0.7, 0.7"/></bsdf>',
            '<bsdf type="conductor" id="white"><string name="material" value="Au"/></bsdf>',
        )
        .replace(
            "</scene>",
            '<emitter type="spot"><rgb name="intensity" value="3, 3, 3"/>'
            '<float name="cutoff_angle" value="25"/><transform name="to_world">'
            '<lookat origin="0, 0, 1.9" target="0, 0, 0" up="0, 1, 0"/></transform></emitter></scene>',
        )
    )
    (cornell / "glossy.xml").write_text(glossy)
    scene = load_mitsuba_xml(cornell / "glossy.xml")
    by_name = {m.name: m for m in scene.materials}
    red, gold = by_name["red"], by_name["white"]
    assert (red.kind, red.spectrum, red.roughness) == ("plastic", "rgb:0.6,0.05,0.05", 0.2)
    assert red.ior == pytest.approx(1.6 / 1.000277, rel=1e-12)  # Mitsuba's ext_ior: air
    assert (gold.kind, gold.metal, gold.roughness, gold.spectrum) == (
        "conductor",
        "Au",
        0.0,
        "flat:0",
    )
    spot = scene.lights[-1]
    assert (spot.kind, spot.spectrum, spot.power, spot.cutoff_deg) == ("spot", "cie:D65", 3.0, 25.0)
    np.testing.assert_allclose(spot.position, [0, 0, 1.9])
    np.testing.assert_allclose(spot.direction, [0, 0, -1], atol=1e-12)


def test_flip_normals_turns_a_rectangle_and_an_area_light_round(cornell):
    flipped = XML.replace(
        '<shape type="rectangle" id="floor"><ref id="white"/>',
        '<shape type="rectangle" id="floor"><ref id="white"/><boolean name="flip_normals" value="true"/>',
    ).replace(
        '<emitter type="area">',
        '<boolean name="flip_normals" value="true"/><emitter type="area">',
    )
    (cornell / "flipped.xml").write_text(flipped)
    plain, turned = (load_mitsuba_xml(cornell / n) for n in ("cornell.xml", "flipped.xml"))
    floor = {s.name: s for s in turned.meshes}["floor"]
    np.testing.assert_array_equal(
        floor.faces, {s.name: s for s in plain.meshes}["floor"].faces[:, ::-1]
    )
    np.testing.assert_allclose(turned.lights[0].direction, [0, 0, 1], atol=1e-12)


def test_a_spectrum_from_an_spd_file_equals_the_written_out_one(cornell):
    lines = "".join(f"{w} {v}\n" for w, v in zip(GREEN["wavelengths"], GREEN["values"]))
    (cornell / "green.spd").write_text("# measured green\n" + lines)
    spd = XML.replace(f'value="{_spectrum(GREEN)}"', 'filename="green.spd"')
    (cornell / "spd.xml").write_text(spd)
    plain, from_file = (load_mitsuba_xml(cornell / n) for n in ("cornell.xml", "spd.xml"))
    assert [m.spectrum for m in plain.materials] == [m.spectrum for m in from_file.materials]
    (record,) = from_file.metadata["spectrum_files"]  # issue 47: .spd files recorded too
    digest = hashlib.sha256((cornell / "green.spd").read_bytes()).hexdigest()
    # relative to the XML file's folder: no path of the building machine is recorded
    assert record == {"spectrum": "spd:green.spd", "file": "green.spd", "sha256": digest}
    assert "spectrum_files" not in plain.metadata
    (cornell / "out.xml").write_text(spd.replace('"green.spd"', '"../green.spd"'))
    with pytest.raises(
        SceneError, match="<spectrum>: filename '../green.spd'; expected a path inside"
    ):
        load_mitsuba_xml(cornell / "out.xml")
