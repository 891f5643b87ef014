"""The .blend importer maps Principled BSDF metallic/roughness/IOR to glossy materials."""

from __future__ import annotations

import pytest

from ._builders import build_blend


def test_principled_metallic_roughness_and_ior(tmp_path):
    from spectrinsic.scenes.blender import load_blend

    out = build_blend("make_blend_gloss.py", tmp_path / "gloss.blend")
    mats = {m.name: m for m in load_blend(out).materials}
    copper, coat, matte = mats["Copper"], mats["munsell:5R 4/14"], mats["flat:0.5"]
    assert (copper.kind, copper.metal, copper.spectrum) == ("conductor", "Cu", "flat:0")
    assert copper.roughness == pytest.approx(0.09, rel=1e-5)  # alpha = roughness squared
    assert (coat.kind, coat.spectrum) == ("plastic", "munsell:5R 4/14")
    assert coat.roughness == pytest.approx(0.04, rel=1e-5) and coat.ior == pytest.approx(
        1.45, rel=1e-5
    )
    assert matte.kind == "diffuse"  # Roughness 0.8: Lambertian, as every material before
    glass = mats["Glass"]  # Transmission 1: clear glass, no diffuse spectrum needed
    assert (glass.kind, glass.spectrum, glass.roughness) == ("dielectric", "flat:0", 0.0)
    assert glass.ior == pytest.approx(1.52, rel=1e-5)


class _Socket:
    def __init__(self, value, linked=False):
        self.default_value, self.is_linked = value, linked


class _Node:
    def __init__(self, type_, **inputs):
        self.type, self.inputs = type_, {k.replace("_", " "): _Socket(v) for k, v in inputs.items()}


class _Mat(dict):
    """A duck-typed ``bpy`` material: a name, custom properties and a node tree."""

    def __init__(self, name, *nodes):
        super().__init__()
        self.name = name
        self.node_tree = type("Tree", (), {"nodes": list(nodes)})()


def _principled(**over):
    inputs = {"Base_Color": (1.0, 1.0, 1.0, 1.0), "Metallic": 0.0, "Roughness": 0.0, "IOR": 1.45}
    return _Node("BSDF_PRINCIPLED", **(inputs | over))


def test_principled_transmission_1_and_a_glass_node_are_clear_glass():
    """No bpy needed: the node reading runs on duck-typed materials."""
    from spectrinsic.scenes.blender import principled_gloss

    glass = principled_gloss(_Mat("Glass", _principled(Transmission_Weight=1.0, Roughness=0.2)))
    assert glass == {"kind": "dielectric", "ior": 1.45, "roughness": pytest.approx(0.04)}
    node = _Node("BSDF_GLASS", Color=(1.0, 1.0, 1.0, 1.0), Roughness=0.0, IOR=1.5)
    assert principled_gloss(_Mat("Pane", node)) == {
        "kind": "dielectric",
        "ior": 1.5,
        "roughness": 0.0,
    }
    assert principled_gloss(_Mat("Paint", _principled(Transmission_Weight=0.0))) == {
        "kind": "plastic", "roughness": 0.0, "ior": pytest.approx(1.45),
    }  # fmt: skip


@pytest.mark.parametrize(
    ("mat", "expected"),
    [
        (_Mat("Mix", _principled(Transmission_Weight=0.5)), "Transmission Weight 0.5"),
        (
            _Mat("Red", _Node("BSDF_GLASS", Color=(1.2, 0.9, 0.2, 1), Roughness=0.0, IOR=1.5)),
            "glass Color",
        ),
    ],
)
def test_partial_or_tinted_blender_glass_is_refused_in_one_line(mat, expected):
    from spectrinsic.errors import SceneError
    from spectrinsic.scenes.blender import principled_gloss

    with pytest.raises(SceneError) as info:
        principled_gloss(mat)
    assert (
        "\n" not in str(info.value)
        and expected in str(info.value)
        and repr(mat.name) in str(info.value)
    )
