"""Tinted glass in every reader: YAML ``transmittance`` and ``specular_reflectance``, Mitsuba
XML ``specular_transmittance`` and ``specular_reflectance``, glTF ``KHR_materials_transmission``
with a ``baseColorFactor``, Blender's Principled Base Color under Transmission 1 and Glass BSDF
Color; a textured tint (and what has no exact counterpart) refused in one line, rc 2 on the
command line before any work."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from trimesh.visual.material import PBRMaterial

from spectrinsic.cli import main
from spectrinsic.errors import SceneError
from spectrinsic.scenes.blender_gloss import principled_gloss
from spectrinsic.scenes.materials import material_entry, parse_material
from spectrinsic.scenes.meshes import load_mesh_scene
from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml
from spectrinsic.scenes.model import Material
from spectrinsic.scenes.scene_reader import load_scene

from ._builders import build_blend, gltf_with_material
from .test_io import BASE, write


def _refused(capsys, path, out, *extra: str) -> str:
    """The one line ``spectrinsic render PATH`` prints on stderr refusing it (rc 2, nothing
    written)."""
    assert main(["render", str(path), "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert not out.exists()
    return err


# -- YAML ------------------------------------------------------------------------------------


def test_yaml_glass_takes_a_transmittance_and_writes_it_back():
    bottle = parse_material("bottle", {"kind": "dielectric", "transmittance": "rgb:0.2,0.6,0.3"})
    assert isinstance(bottle, Material) and bottle.tinted
    assert material_entry(bottle) == {
        "kind": "dielectric", "ior": 1.5, "roughness": 0.0, "transmittance": "rgb:0.2,0.6,0.3",
    }  # fmt: skip
    assert parse_material("bottle", material_entry(bottle)) == bottle
    clear = parse_material("pane", {"kind": "thindielectric"})
    assert (
        isinstance(clear, Material)
        and not clear.tinted
        and "transmittance" not in str(material_entry(clear))
    )


@pytest.mark.parametrize(
    ("entry", "expected"),
    [
        ({"kind": "plastic", "spectrum": "flat:0.5", "transmittance": "flat:0.5"}, "unknown key"),
        ({"kind": "dielectric", "transmittance": 0.5}, "expected a non-empty spectrum name"),
        ({"kind": "dielectric", "transmittance": {"kind": "textured"}}, "transmittance"),
    ],
)
def test_yaml_transmittance_off_glass_or_not_a_spectrum_name_is_refused(entry, expected):
    problem = parse_material("m", entry)
    assert isinstance(problem, str) and expected in problem


def test_yaml_tinted_glass_loads_and_a_bad_tint_is_refused_on_the_command_line(tmp_path, capsys):
    doc = dict(BASE)
    doc["materials"] = BASE["materials"] | {
        "red": {"kind": "dielectric", "transmittance": "munsell:5G 6/8"}
    }
    (glass,) = [m for m in load_scene(write(tmp_path, doc)).materials if m.transmissive]
    assert glass.transmittance == "munsell:5G 6/8"
    doc["materials"] = BASE["materials"] | {
        "red": {"kind": "dielectric", "transmittance": "munsel:5G 6/8"}
    }
    err = _refused(capsys, write(tmp_path, doc), tmp_path / "out")
    assert ".transmittance" in err and "munsel:5G 6/8" in err


# -- Mitsuba XML -----------------------------------------------------------------------------

_XML = """<scene version="3.0.0">
  <bsdf type="diffuse" id="white"><spectrum name="reflectance" value="0.7"/></bsdf>
  {glass}
  <shape type="rectangle" id="floor"><ref id="white"/></shape>
  <shape type="sphere" id="gem"><ref id="glass"/>
    <transform name="to_world"><scale value="0.3"/><translate value="0 0 0.5"/></transform>
  </shape>
  <emitter type="point"><point name="position" value="0, -1, 2"/>
    <spectrum name="intensity" value="5"/></emitter>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, -3, 1" target="0, 0, 0.5" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
  </sensor>
</scene>
"""


def _xml(tmp_path, glass: str):
    path = tmp_path / "gem.xml"
    path.write_text(_XML.format(glass=glass))
    return path


@pytest.mark.parametrize(
    ("tint", "expected"),
    [
        ('<rgb name="specular_transmittance" value="0.5, 0.9, 0.5"/>', "rgb:0.5,0.9,0.5"),
        ('<float name="specular_transmittance" value="0.6"/>', "flat:0.6"),
        (
            '<spectrum name="specular_transmittance" value="400:0.2, 700:0.9"/>',
            "inline:reflectance:400.0=0.2,700.0=0.9",
        ),
        ('<float name="specular_transmittance" value="1"/>', ""),
    ],
)
def test_xml_specular_transmittance_is_the_glass_transmittance(tmp_path, tint, expected):
    for plugin in ("dielectric", "thindielectric"):
        glass = f'<bsdf type="{plugin}" id="glass">{tint}</bsdf>'
        (gem,) = [m for m in load_mitsuba_xml(_xml(tmp_path, glass)).materials if m.transmissive]
        assert (gem.kind, gem.transmittance) == (plugin, expected)


_BITMAP_TINT = (
    '<bsdf type="dielectric" id="glass"><texture type="bitmap" name="specular_transmittance">'
    '<string name="filename" value="tint.png"/></texture></bsdf>'
)


def test_xml_a_textured_tint_is_refused_in_one_line_or_taken_as_clear(tmp_path, capsys):
    from PIL import Image

    Image.fromarray(np.full((4, 4, 3), 128, np.uint8)).save(tmp_path / "tint.png")
    path = _xml(tmp_path, _BITMAP_TINT)
    with pytest.raises(SceneError, match="textured tint"):
        load_mitsuba_xml(path)
    err = _refused(capsys, path, tmp_path / "out")
    assert "specular_transmittance" in err and "textured tint" in err
    scene = load_mitsuba_xml(path, approximate=True)
    (gem,) = [m for m in scene.materials if m.transmissive]
    assert gem.transmittance == ""
    (said,) = scene.metadata["approximated"]
    assert "textured specular_transmittance taken as 1" in said


@pytest.mark.parametrize(
    ("tint", "expected"),
    [
        ('<rgb name="specular_reflectance" value="0.5, 0.9, 0.5"/>', "rgb:0.5,0.9,0.5"),
        ('<float name="specular_reflectance" value="0.6"/>', "flat:0.6"),
        (
            '<spectrum name="specular_reflectance" value="400:0.2, 700:0.9"/>',
            "inline:reflectance:400.0=0.2,700.0=0.9",
        ),
        ('<float name="specular_reflectance" value="1"/>', ""),
    ],
)
def test_xml_specular_reflectance_is_the_glass_reflection_tint(tmp_path, tint, expected):
    """On every glass plugin, as ``specular_transmittance``; the other tint stays clear."""
    ggx = '<string name="distribution" value="ggx"/><float name="alpha" value="0.2"/>'
    for plugin in ("dielectric", "thindielectric", "roughdielectric"):
        rough = ggx if plugin == "roughdielectric" else ""
        glass = f'<bsdf type="{plugin}" id="glass">{rough}{tint}</bsdf>'
        (gem,) = [m for m in load_mitsuba_xml(_xml(tmp_path, glass)).materials if m.transmissive]
        assert (gem.specular_reflectance, gem.transmittance) == (expected, "")
        assert gem.tinted == bool(expected)


def test_xml_a_textured_reflection_tint_or_a_tinted_plastic_is_refused(tmp_path, capsys):
    """A ``bitmap`` reflection tint on glass, and any ``specular_reflectance`` on a plastic
    (it scales the coat's reflection, which the band path does not tint), are refused in one
    line (rc 2 from the command line); a conductor's is read."""
    from PIL import Image

    Image.fromarray(np.full((4, 4, 3), 128, np.uint8)).save(tmp_path / "tint.png")
    path = _xml(tmp_path, _BITMAP_TINT.replace("specular_transmittance", "specular_reflectance"))
    err = _refused(capsys, path, tmp_path / "out")
    assert "specular_reflectance" in err and "textured tint" in err
    coat = (
        '<bsdf type="plastic" id="glass">'
        '<rgb name="specular_reflectance" value="0.5, 0.9, 0.5"/></bsdf>'
    )
    err = _refused(capsys, _xml(tmp_path, coat), tmp_path / "out")
    assert "specular_reflectance [0.5, 0.9, 0.5]" in err and "only 1" in err
    mirror = coat.replace('"plastic"', '"conductor"').replace(
        "<rgb", '<string name="material" value="none"/><rgb'
    )
    (foil,) = [m for m in load_mitsuba_xml(_xml(tmp_path, mirror)).materials if m.metal]
    assert (foil.kind, foil.metal, foil.specular_reflectance) == (
        "conductor",
        "none",
        "rgb:0.5,0.9,0.5",
    )


# -- glTF ------------------------------------------------------------------------------------


def _gltf(tmp_path, extensions: dict, pbr: dict, textured: bool = False):
    """A .gltf of one box whose material 'glass' carries *extensions* and *pbr* factors (and,
    *textured*, a base colour image on its texture coordinates)."""
    from PIL import Image

    box = trimesh.creation.box((1.0, 1.0, 1.0))
    box.apply_translation((0.0, 0.0, 0.5))
    image = Image.fromarray(np.full((4, 4, 3), 200, np.uint8)) if textured else None
    uv = np.random.default_rng(0).random((len(box.vertices), 2)) if textured else None
    material = PBRMaterial(name="glass", baseColorTexture=image)
    box.visual = trimesh.visual.TextureVisuals(uv=uv, material=material)
    path = gltf_with_material(tmp_path, box, extensions, pbr)
    written = json.loads(path.read_text())["materials"][0]["pbrMetallicRoughness"]
    assert textured == ("baseColorTexture" in written)
    return path


_TRANSMISSION = {"KHR_materials_transmission": {"transmissionFactor": 1.0}}


def test_gltf_a_base_colour_factor_tints_the_glass(tmp_path):
    pbr = {"baseColorFactor": [0.2, 0.9, 0.25, 1.0], "roughnessFactor": 0.0}
    (pane,) = load_mesh_scene(
        _gltf(tmp_path, _TRANSMISSION, pbr), materials={}, width=8, height=8
    ).materials
    assert (pane.kind, pane.transmittance) == ("thindielectric", "rgb:0.2,0.9,0.25")
    solid = _TRANSMISSION | {"KHR_materials_volume": {"thicknessFactor": 0.1}}
    (gem,) = load_mesh_scene(_gltf(tmp_path, solid, pbr), materials={}, width=8, height=8).materials
    assert (gem.kind, gem.transmittance) == ("dielectric", "rgb:0.2,0.9,0.25")
    plain = {"KHR_materials_specular": {"specularFactor": 1, "specularColorFactor": [1, 1, 1]}}
    (gem,) = load_mesh_scene(
        _gltf(tmp_path, solid | plain, pbr), materials={}, width=8, height=8
    ).materials  # KHR_materials_specular at its defaults changes nothing
    assert (gem.transmittance, gem.specular_reflectance) == ("rgb:0.2,0.9,0.25", "")


@pytest.mark.parametrize(
    ("extensions", "pbr", "expected"),
    [
        (
            _TRANSMISSION,
            {"roughnessFactor": 0.0},
            "textured tint",
        ),
        (
            _TRANSMISSION
            | {"KHR_materials_volume": {"thicknessFactor": 0.1, "attenuationDistance": 0.5}},
            {"roughnessFactor": 0.0},
            "volume attenuation",
        ),
        (
            _TRANSMISSION,
            {"baseColorFactor": [1.5, 0.5, 0.5, 1.0]},
            "expected 3 or 4 numbers in [0, 1]",
        ),
        (
            _TRANSMISSION | {"KHR_materials_specular": {"specularColorFactor": [1, 0.5, 0.5]}},
            {"roughnessFactor": 0.0},
            "no exact reflection tint",
        ),
    ],
)
def test_gltf_a_textured_tint_or_an_absorbing_volume_is_refused_in_one_line(
    tmp_path, capsys, extensions, pbr, expected
):
    path = _gltf(tmp_path, extensions, pbr, textured=expected == "textured tint")
    with pytest.raises(SceneError) as info:
        load_mesh_scene(path, materials={}, width=8, height=8)
    assert "\n" not in str(info.value) and "'glass'" in str(info.value)
    err = _refused(capsys, path, tmp_path / "out")
    assert expected in err and "'glass'" in err


# -- Blender (duck-typed bpy, as tests/scenes/test_blender_gloss.py) ---------------------------


class _Socket:
    def __init__(self, value, linked=False):
        self.default_value, self.is_linked = value, linked


class _Node:
    def __init__(self, type_, linked=(), **inputs):
        self.type = type_
        self.inputs = {
            k.replace("_", " "): _Socket(v, k.replace("_", " ") in linked)
            for k, v in inputs.items()
        }


class _Mat(dict):
    def __init__(self, name, *nodes):
        super().__init__()
        self.name = name
        self.node_tree = type("Tree", (), {"nodes": list(nodes)})()


def _principled(linked=(), **over):
    inputs = {"Base_Color": (1.0, 1.0, 1.0, 1.0), "Metallic": 0.0, "Roughness": 0.0, "IOR": 1.45}
    return _Node("BSDF_PRINCIPLED", linked, **(inputs | over))


def test_blender_principled_base_color_tints_each_crossing_by_its_square_root():
    """Cycles tints a Principled glass's transmission by √(Base Color), so a solid's entry and
    exit give Base Color."""
    mat = _Mat("Bottle", _principled(Transmission_Weight=1.0, Base_Color=(0.25, 0.81, 0.36, 1)))
    assert principled_gloss(mat) == {
        "kind": "dielectric", "ior": 1.45, "roughness": 0.0, "transmittance": "rgb:0.5,0.9,0.6",
    }  # fmt: skip
    clear = principled_gloss(_Mat("Clear", _principled(Transmission=1.0)))
    assert "transmittance" not in clear


@pytest.mark.parametrize(
    ("mat", "expected"),
    [
        (
            _Mat("Stained", _principled(("Base Color",), Transmission_Weight=1.0)),
            "fed by a node",
        ),
        (
            _Mat(
                "Green", _Node("BSDF_GLASS", ("Color",), Color=(1, 1, 1, 1), Roughness=0.0, IOR=1.5)
            ),
            "Color fed by a node",
        ),
        (
            _Mat("Old", _principled(Transmission=1.0, Base_Color=(0.2, 0.9, 0.2, 1))),
            "Blender 3.x",
        ),
    ],
)
def test_blender_a_textured_tint_is_refused_in_one_line(mat, expected):
    with pytest.raises(SceneError) as info:
        principled_gloss(mat)
    message = str(info.value)
    assert "\n" not in message and expected in message and repr(mat.name) in message


def test_a_csv_tint_is_read_inside_the_scene_folder_and_one_outside_is_refused(tmp_path):
    """A YAML ``transmittance`` takes ``csv:`` and inline spectra as ``spectrum`` does,
    confined to the scene's folder."""
    rows = "\n".join(f"{w},{20 + 60 * (w - 380) / 400:.3f}" for w in range(380, 781, 10))
    (tmp_path / "tint.csv").write_text("wavelength [nm],bottle [%]\n" + rows + "\n")
    doc = dict(BASE)
    doc["materials"] = BASE["materials"] | {
        "red": {"kind": "dielectric", "transmittance": "csv:tint.csv#bottle"}
    }
    (glass,) = [m for m in load_scene(write(tmp_path, doc)).materials if m.transmissive]
    assert glass.transmittance == f"csv:{(tmp_path / 'tint.csv').resolve()}#bottle"
    doc["materials"] = BASE["materials"] | {
        "red": {"kind": "dielectric", "transmittance": "csv:../tint.csv#bottle"}
    }
    with pytest.raises(SceneError, match="leads outside the scene's folder"):
        load_scene(write(tmp_path, doc))


def test_an_opacity_mask_on_tinted_glass_is_refused_in_one_line(tmp_path):
    """The band path cannot tell a mask's hole from a transmission through the glass."""
    glass = (
        '<bsdf type="mask" id="glass"><float name="opacity" value="0.5"/>'
        '<bsdf type="dielectric"><rgb name="specular_transmittance" value="0.5, 0.9, 0.5"/>'
        "</bsdf></bsdf>"
    )
    path = _xml(tmp_path, glass)  # the mask on the floor (a mask needs texture coordinates)
    text = path.read_text().replace('id="floor"><ref id="white"/>', 'id="floor"><ref id="glass"/>')
    path.write_text(text.replace('id="gem"><ref id="glass"/>', 'id="gem"><ref id="white"/>'))
    with pytest.raises(SceneError) as info:
        load_mitsuba_xml(path)
    assert "\n" not in str(info.value) and "opacity mask on tinted glass" in str(info.value)


def test_a_blend_file_reads_a_principled_tint_and_refuses_a_textured_one(tmp_path, capsys):
    """Through bpy: Base Color (0.25, 0.5625, 0.0625) under Transmission 1 is the
    transmittance ``rgb:0.5,0.75,0.25`` (its square roots, exact in float32); an Image Texture
    feeding the Base Color is refused in one line, rc 2 before any work."""
    from spectrinsic.scenes.blender import load_blend

    for tint in ("0.25,0.5625,0.0625", "textured"):
        out = build_blend("make_blend_gloss.py", tmp_path / f"{tint[:4]}.blend", tint)
        if tint == "textured":
            err = _refused(capsys, out, tmp_path / "out")
            assert "'Glass'" in err and "fed by a node" in err
        else:
            (glass,) = [m for m in load_blend(out).materials if m.transmissive]
            assert glass.transmittance == "rgb:0.5,0.75,0.25"


def test_blender_glass_bsdf_color_tints_reflection_and_transmission_alike():
    """Cycles' Glass BSDF sets the Fresnel's reflection and transmission tints both to its
    Color, once per interaction (no square root, unlike the Principled)."""
    node = _Node("BSDF_GLASS", Color=(0.25, 0.5, 0.75, 1), Roughness=0.0, IOR=1.5)
    assert principled_gloss(_Mat("Green", node)) == {
        "kind": "dielectric", "ior": 1.5, "roughness": 0.0,
        "transmittance": "rgb:0.25,0.5,0.75", "specular_reflectance": "rgb:0.25,0.5,0.75",
    }  # fmt: skip


def test_a_blend_file_reads_a_glass_bsdf_color_as_both_tints_and_refuses_a_textured_one(
    tmp_path, capsys
):
    """Through bpy: a Glass BSDF of Color (0.25, 0.5625, 0.0625) is glass whose transmittance
    and reflection tint are both that colour; an Image Texture feeding its Color is refused in
    one line, rc 2 before any work."""
    from spectrinsic.scenes.blender import load_blend

    for tint in ("0.25,0.5625,0.0625", "textured"):
        out = tmp_path / f"glass-{tint[:4]}.blend"
        build_blend("make_blend_gloss.py", out, f"glass-bsdf:{tint}")
        if tint == "textured":
            err = _refused(capsys, out, tmp_path / "out")
            assert "'Glass'" in err and "Color fed by a node" in err
        else:
            (glass,) = [m for m in load_blend(out).materials if m.transmissive]
            expected = "rgb:0.25,0.5625,0.0625"
            assert (glass.transmittance, glass.specular_reflectance) == (expected, expected)
            assert (glass.kind, glass.ior) == ("dielectric", pytest.approx(1.52))


def test_yaml_glass_takes_a_reflection_tint_and_writes_it_back():
    gem = {"kind": "dielectric", "transmittance": "flat:0.5", "specular_reflectance": "rgb:1,0,0"}
    parsed = parse_material("gem", gem)
    assert isinstance(parsed, Material) and parsed.tinted
    assert parsed.specular_reflectance == "rgb:1,0,0"
    assert material_entry(parsed) == gem | {"ior": 1.5, "roughness": 0.0}
    assert parse_material("gem", material_entry(parsed)) == parsed
    only = parse_material("pane", {"kind": "thindielectric", "specular_reflectance": "flat:0.2"})
    assert isinstance(only, Material) and only.tinted and only.transmittance == ""
    foil = {"kind": "conductor", "metal": "none", "specular_reflectance": "flat:0.5"}
    parsed = parse_material("foil", foil)  # a coloured mirror
    assert isinstance(parsed, Material) and not parsed.tinted  # tinted: glass only
    assert material_entry(parsed) == foil | {"roughness": 0.0}
    assert "unknown key 'specular_reflectance'" in parse_material(
        "coat", {"kind": "plastic", "spectrum": "flat:0.5", "specular_reflectance": "flat:0.5"}
    )
