"""The mesh importer maps glTF pbrMetallicRoughness factors to glossy materials."""

from __future__ import annotations

import pytest
import trimesh
from trimesh.visual.material import PBRMaterial

from spectrinsic.scenes.meshes import load_mesh_scene

from ._builders import gltf_with_material


def _box(name: str, offset: float, material: PBRMaterial | None) -> trimesh.Trimesh:
    box = trimesh.creation.box((1.0, 1.0, 1.0))
    box.apply_translation((offset, 0.0, 0.5))
    if material is not None:
        box.visual = trimesh.visual.TextureVisuals(material=material)
    box.metadata["name"] = name
    return box


def test_gltf_metallic_roughness_factors(tmp_path):
    scene = trimesh.Scene()
    scene.add_geometry(
        _box("a", -1.5, PBRMaterial(name="steel", metallicFactor=1.0, roughnessFactor=0.3)), "a"
    )
    scene.add_geometry(
        _box("b", 0.0, PBRMaterial(name="lacquer", metallicFactor=0.0, roughnessFactor=0.2)), "b"
    )
    scene.add_geometry(
        _box("c", 1.5, PBRMaterial(name="clay", metallicFactor=0.0, roughnessFactor=0.9)), "c"
    )
    path = tmp_path / "three.glb"
    scene.export(path)
    loaded = load_mesh_scene(
        path, materials={"lacquer": "munsell:5R 4/14", "clay": "flat:0.5"}, width=16, height=16
    )
    by_kind = {m.kind: m for m in loaded.materials}
    assert set(by_kind) == {"conductor", "plastic", "diffuse"}
    assert by_kind["conductor"].metal == "Al" and by_kind["conductor"].roughness == pytest.approx(
        0.09, rel=1e-5
    )
    assert by_kind["plastic"].spectrum == "munsell:5R 4/14" and by_kind[
        "plastic"
    ].roughness == pytest.approx(0.04)
    assert (
        by_kind["diffuse"].name == "flat:0.5"
    )  # matte materials are named after their spectrum, as before


def test_an_obj_usemtl_without_a_library_keeps_its_names(tmp_path):
    """Issue 47: ``usemtl paint`` with no ``mtllib`` names the material ``paint``, not
    ``cube.obj_1`` (trimesh drops names no library defines)."""
    from spectrinsic.scenes.meshes import load_mesh_scene

    obj = tmp_path / "cube.obj"
    obj.write_text(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
        "usemtl paint\nf 1 2 3\nf 1 3 4\nusemtl wood\nf 1 2 5\n"
    )
    mapping = {"paint": "munsell:5R 4/14", "wood": "munsell:5YR 5/6"}
    scene = load_mesh_scene(obj, materials=mapping, width=16, height=16)
    assert sorted(m.spectrum for m in scene.materials) == ["munsell:5R 4/14", "munsell:5YR 5/6"]
    faces = {m.name: len(m.faces) for m in scene.meshes}
    assert faces == {"paint": 2, "wood": 1}


def _gltf_with(tmp_path, extensions: dict, pbr: dict | None = None):
    """A .gltf of one box whose material 'glass' carries *extensions* (and *pbr* factors)."""
    box = _box("pane", 0.0, PBRMaterial(name="glass", roughnessFactor=0.0))
    return gltf_with_material(tmp_path, box, extensions, pbr or {})


def test_gltf_transmission_1_is_clear_glass_thin_without_a_volume(tmp_path):
    """``KHR_materials_transmission`` 1: a thin pane without ``KHR_materials_volume`` (glTF's
    thin-walled default), a solid dielectric of ``KHR_materials_ior``'s index with one."""
    full = {"KHR_materials_transmission": {"transmissionFactor": 1.0}}
    (pane,) = load_mesh_scene(_gltf_with(tmp_path, full), materials={}, width=8, height=8).materials
    assert (pane.kind, pane.ior, pane.spectrum) == ("thindielectric", 1.5, "flat:0")
    solid = full | {
        "KHR_materials_volume": {"thicknessFactor": 0.1},
        "KHR_materials_ior": {"ior": 1.33},
    }
    pbr = {"roughnessFactor": 0.3}
    path = _gltf_with(tmp_path, solid, pbr)
    (glass,) = load_mesh_scene(path, materials={}, width=8, height=8).materials
    assert (glass.kind, glass.ior) == ("dielectric", 1.33)
    assert glass.roughness == pytest.approx(0.09)


@pytest.mark.parametrize(
    ("extensions", "pbr", "expected"),
    [
        (
            {"KHR_materials_transmission": {"transmissionFactor": 0.5}},
            None,
            "transmissionFactor 0.5",
        ),
        (
            {
                "KHR_materials_transmission": {"transmissionFactor": 1.0},
                "KHR_materials_volume": {"attenuationColor": [0.2, 0.9, 0.2]},
            },
            None,
            "volume attenuation",
        ),
        (
            {"KHR_materials_transmission": {"transmissionFactor": 1.0}},
            {"roughnessFactor": 0.5},
            "thin-walled",
        ),
    ],
)
def test_gltf_partial_or_tinted_transmission_is_refused_in_one_line(
    tmp_path, extensions, pbr, expected
):
    from spectrinsic.errors import SceneError

    path = _gltf_with(tmp_path, extensions, pbr)
    with pytest.raises(SceneError) as info:
        load_mesh_scene(path, materials={}, width=8, height=8)
    message = str(info.value)
    assert "\n" not in message and "'glass'" in message and expected in message
