"""Glossy materials in scene files (spectrinsic/scenes/materials.py): parsing, round trips, one-line errors,
and the records of matte scenes left as they were."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml

from spectrinsic.errors import SceneError
from spectrinsic.scenes.model import Material, scene_hash, scene_to_dict
from spectrinsic.scenes.scene_reader import load_scene
from spectrinsic.scenes.scene_writer import save_scene
from spectrinsic.spectra.conductors import conductor_ior, conductor_names, fresnel_conductor

from .test_io import BASE, render_refusal, write

GLOSSY = {
    "red": {"kind": "plastic", "spectrum": "munsell:5R 4/14", "ior": 1.6, "roughness": 0.2},
    "ground": {"kind": "conductor", "metal": "Cu"},
}


def _doc(materials: dict) -> dict:
    doc = copy.deepcopy(BASE)
    doc["materials"] = materials
    return doc


def test_glossy_materials_load_and_round_trip(tmp_path):
    scene = load_scene(write(tmp_path, _doc(GLOSSY)))
    red, ground = scene.materials
    assert (red.kind, red.spectrum, red.ior, red.roughness) == (
        "plastic",
        "munsell:5R 4/14",
        1.6,
        0.2,
    )
    assert (ground.kind, ground.metal, ground.spectrum, ground.roughness) == (
        "conductor",
        "Cu",
        "flat:0",
        0.0,
    )
    again = load_scene(save_scene(scene, tmp_path / "saved.yaml"))
    assert again == scene and scene_hash(again) == scene_hash(scene)


def test_glass_and_a_perfect_mirror_load_and_round_trip(tmp_path):
    """``dielectric`` (rough or smooth), ``thindielectric`` and the mirror ``metal: none``:
    no diffuse lobe (spectrum ``flat:0``), written back to the same entries."""
    entries = {
        "red": {"kind": "dielectric", "ior": 1.5, "roughness": 0.1},
        "ground": {"kind": "thindielectric", "ior": 1.52},
        "mirror": {"kind": "conductor", "metal": "none", "roughness": 0.0},
    }
    scene = load_scene(write(tmp_path, _doc(entries)))
    vase, pane, _ = scene.materials
    assert (vase.kind, vase.ior, vase.roughness, vase.spectrum) == (
        "dielectric",
        1.5,
        0.1,
        "flat:0",
    )
    assert (pane.kind, pane.ior, pane.spectrum) == ("thindielectric", 1.52, "flat:0")
    assert all(m.non_diffuse for m in scene.materials)
    assert [m.transmissive for m in scene.materials] == [True, True, False]
    saved = yaml.safe_load(save_scene(scene, tmp_path / "saved.yaml").read_text())
    assert saved["materials"] == entries
    again = load_scene(tmp_path / "saved.yaml")
    assert again == scene and scene_hash(again) == scene_hash(scene)


def test_matte_records_have_no_gloss_keys(tmp_path):
    """Lambertian materials are written as before (a spectrum name; no new keys in the scene
    record), so matte scenes keep their hashes and seeds."""
    scene = load_scene(write(tmp_path, BASE))
    assert scene_to_dict(scene)["materials"] == [
        {"name": "red", "spectrum": "munsell:5R 4/14"},
        {"name": "ground", "spectrum": "flat:0.5"},
    ]
    saved = yaml.safe_load(save_scene(scene, tmp_path / "saved.yaml").read_text())
    assert saved["materials"] == BASE["materials"]


@pytest.mark.parametrize(
    ("entry", "expected"),
    [
        ({"kind": "conductor", "metal": "Gold"}, "unknown conductor 'Gold'"),
        ({"kind": "plastic", "spectrum": "munsell:5R 4/14", "ior": 0.9}, "ior 0.9"),
        ({"kind": "plastic", "spectrum": "munsell:5R 4/14", "roughness": -0.1}, "roughness -0.1"),
        (
            {"kind": "plastic", "spectrum": "munsell:5R 4/14", "roughness": "high"},
            "roughness: expected a number",
        ),
        ({"kind": "glass", "spectrum": "munsell:5R 4/14"}, "kind 'glass'"),
        ({"kind": "conductor", "metal": "Au", "spectrum": "flat:0.5"}, "unknown key 'spectrum'"),
        ({"kind": "plastic", "ior": 1.5}, "needs a non-empty 'spectrum'"),
        ({"kind": "dielectric", "spectrum": "flat:0.5"}, "unknown key 'spectrum'"),
        ({"kind": "dielectric", "ior": 1.0}, "ior 1.0"),
        ({"kind": "thindielectric", "roughness": 0.2}, "unknown key 'roughness'"),
        (["munsell:5R 4/14"], "expected a spectrum name or a mapping"),
    ],
)
def test_bad_materials_give_one_line_naming_the_field(tmp_path, entry, expected):
    path = write(tmp_path, _doc({"red": entry, "ground": "flat:0.5"}))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    assert (
        "\n" not in message
        and message.startswith(f"{path}: materials.red: ")
        and expected in message
    )


def test_programmatic_scenes_are_validated_too(tmp_path):
    from dataclasses import replace

    from spectrinsic.scenes.validate import validate_scene

    scene = load_scene(write(tmp_path, BASE))
    bad = replace(
        scene,
        materials=(
            Material("red", "munsell:5R 4/14", kind="conductor", metal="Au"),
            scene.materials[1],
        ),
    )
    with pytest.raises(
        SceneError, match=r"materials\[0\] \('red'\): a conductor has no diffuse spectrum"
    ):
        validate_scene(bad)


def test_cli_rejects_a_bad_material_before_any_work(tmp_path):
    path = write(
        tmp_path, _doc({"red": {"kind": "conductor", "metal": "Unobtainium"}, "ground": "flat:0.5"})
    )
    assert "unknown conductor 'Unobtainium'" in render_refusal(path, tmp_path / "out")


def test_conductor_tables_and_fresnel():
    """Mitsuba's tables are found by name; the conductor Fresnel formula reduces to the
    normal-incidence closed form and to the dielectric one for k = 0 at grazing angles."""
    assert {"Ag", "Al", "Au", "Cu"} <= set(conductor_names())
    eta, k = conductor_ior("Au", np.array([450.0, 650.0]))
    f0 = fresnel_conductor(np.ones(2), eta, k)
    np.testing.assert_allclose(f0, ((eta - 1) ** 2 + k**2) / ((eta + 1) ** 2 + k**2), rtol=1e-12)
    assert f0[1] > 0.9 > 0.4 > f0[0]  # gold: red reflected, blue absorbed
    mu = np.linspace(0.05, 1, 20)
    sin_t = np.sqrt(1 - mu**2) / 1.5
    cos_t = np.sqrt(1 - sin_t**2)
    dielectric = 0.5 * (
        ((mu - 1.5 * cos_t) / (mu + 1.5 * cos_t)) ** 2
        + ((1.5 * mu - cos_t) / (1.5 * mu + cos_t)) ** 2
    )
    np.testing.assert_allclose(fresnel_conductor(mu, 1.5, 0.0), dielectric, rtol=1e-9)
