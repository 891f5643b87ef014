"""The .blend importer: a small file built with bpy (in a subprocess) read back in world space."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.errors import MissingDependencyError, SceneError

from ._builders import build_blend

#: Blender stores vertex coordinates and matrices in float32.
FLOAT32 = 1e-6


def make_blend(
    folder: Path, *, camera: bool = True, unknown_material: bool = False
) -> tuple[Path, Path]:
    """``test.blend`` of ``make_blend.py`` in *folder*, and the file its text block would write
    if Blender ran it."""
    out, marker = folder / "test.blend", folder / "autorun-ran.txt"
    options = str(marker), "1" if camera else "0", "1" if unknown_material else "0"
    return build_blend("make_blend.py", out, *options), marker


@pytest.fixture(scope="module")
def blend_file(tmp_path_factory):
    return make_blend(tmp_path_factory.mktemp("blend"))


@pytest.fixture(scope="module")
def imported(blend_file):
    from spectrinsic.scenes.blender import load_blend

    path, _ = blend_file
    return load_blend(path, materials={"Paint": "munsell:5PB 4/10"})


@pytest.mark.blender
def test_meshes_are_in_world_space(imported):
    cube = next(m for m in imported.meshes if m.name == "Cube")
    # unit cube scaled (2, 1, 1), turned 90 deg about z, moved to (1, 2, 0.5)
    np.testing.assert_allclose(cube.vertices.min(axis=0), [0.5, 1.0, 0.0], atol=FLOAT32)
    np.testing.assert_allclose(cube.vertices.max(axis=0), [1.5, 3.0, 1.0], atol=FLOAT32)
    assert cube.faces.shape == (12, 3)  # 6 quads triangulated
    ground = next(m for m in imported.meshes if m.name == "Ground")
    np.testing.assert_allclose(ground.vertices[:, 2], -0.1, atol=FLOAT32)


@pytest.mark.blender
def test_materials_map_by_name_property_and_mapping(imported):
    spectra = {m.name: m.spectrum for m in imported.materials}
    assert spectra == {
        "munsell:5R 4/14": "munsell:5R 4/14",
        "Paint": "munsell:5PB 4/10",
        "Floor": "flat:0.5",
    }
    cube = next(m for m in imported.meshes if m.name == "Cube")
    used = [imported.materials[i].name for i in cube.face_materials]
    # 4 quads -> 8 triangles of the first slot, 2 quads -> 4 of the second
    assert sorted(used) == ["Paint"] * 4 + ["munsell:5R 4/14"] * 8


@pytest.mark.blender
def test_camera_pose_fov_and_resolution(imported):
    cam = imported.camera
    np.testing.assert_allclose(cam.origin, [1.0, -6.0, 0.5], atol=FLOAT32)
    forward = np.subtract(cam.target, cam.origin)
    np.testing.assert_allclose(forward / np.linalg.norm(forward), [0, 1, 0], atol=FLOAT32)
    np.testing.assert_allclose(cam.up, [0, 0, 1], atol=FLOAT32)
    # 35 mm lens on a 36 mm sensor fitted horizontally
    assert cam.fov_deg == pytest.approx(math.degrees(2 * math.atan(18 / 35)), rel=1e-6)
    assert (cam.width, cam.height) == (64, 48)


@pytest.mark.blender
def test_lights_kinds_spectra_and_powers(imported):
    lights = {light.name: light for light in imported.lights}
    assert {n: light.kind for n, light in lights.items()} == {
        "Lamp": "point",
        "Spot": "spot",
        "Panel": "area",
        "Sun": "directional",
    }
    assert lights["Lamp"].spectrum == "planck:2800K"  # custom property
    assert lights["Sun"].spectrum == "cie:D65"  # default
    # Blender watts -> radiant intensity P / 4 pi, radiance P / (pi A), sun strength as is
    assert lights["Lamp"].power == pytest.approx(100 / (4 * math.pi))
    assert lights["Spot"].power == pytest.approx(200 / (4 * math.pi))
    assert lights["Spot"].cutoff_deg == pytest.approx(30.0, abs=1e-5)
    np.testing.assert_allclose(
        lights["Spot"].direction, [-math.sqrt(0.5), 0, -math.sqrt(0.5)], atol=FLOAT32
    )
    assert lights["Panel"].size == pytest.approx((0.5, 0.25))
    assert lights["Panel"].power == pytest.approx(50 / (math.pi * 0.5 * 0.25))
    np.testing.assert_allclose(lights["Panel"].direction, [0, 0, -1], atol=FLOAT32)
    assert lights["Sun"].power == pytest.approx(3.0)
    np.testing.assert_allclose(lights["Sun"].direction, [0, 0.5, -math.sqrt(0.75)], atol=FLOAT32)
    np.testing.assert_allclose(lights["Lamp"].position, [0, 0, 4], atol=FLOAT32)


@pytest.mark.blender
def test_file_scripts_never_run(blend_file, imported):
    _, marker = blend_file
    assert imported.meshes  # the file was opened ...
    assert not marker.exists()  # ... but its registered text block did not run


@pytest.mark.blender
def test_blend_without_camera(tmp_path):
    from spectrinsic.scenes.blender import load_blend

    path, _ = make_blend(tmp_path, camera=False)
    with pytest.raises(SceneError, match=r"test\.blend: camera: the \.blend has no camera"):
        load_blend(path, materials={"Paint": "munsell:5PB 4/10"})


@pytest.mark.blender
def test_blend_with_unknown_spectrum(tmp_path):
    from spectrinsic.scenes.blender import load_blend

    path, _ = make_blend(tmp_path, unknown_material=True)
    with pytest.raises(
        SceneError, match=r"test\.blend: material 'Floor': unknown Munsell chip '5R 4/15'"
    ) as info:
        load_blend(path, materials={"Paint": "munsell:5PB 4/10"})
    assert "\n" not in str(info.value)
    # an unmapped material named like nothing is reported with the ways to map it
    with pytest.raises(SceneError, match="material 'Paint'.*materials="):
        load_blend(path, materials={"Floor": "flat:0.5"}, colours_from_asset=False)


@pytest.mark.blender
def test_base_colour_unless_turned_off(blend_file):
    """An unmapped material is an error without colours_from_asset; with it (the default since
    issue 41) its Principled Base
    Color becomes an rgb: reflectance, while a name or property that is a spectrum still wins."""
    from spectrinsic.scenes.blender import load_blend

    path, _ = blend_file
    with pytest.raises(SceneError, match="material 'Paint'.*materials="):
        load_blend(path, colours_from_asset=False)
    scene = load_blend(path)
    spectra = {m.name: m.spectrum for m in scene.materials}
    assert spectra.pop("munsell:5R 4/14") == "munsell:5R 4/14"
    assert spectra.pop("Floor") == "flat:0.5"
    paint = spectra.pop("Paint")
    assert paint.startswith("rgb:") and not spectra
    rgb = [float(c) for c in paint.removeprefix("rgb:").split(",")]
    np.testing.assert_allclose(rgb, [0.2, 0.3, 0.6], atol=FLOAT32)


def test_missing_bpy_gives_a_helpful_error(monkeypatch, tmp_path):
    from spectrinsic.scenes.blender import load_blend

    monkeypatch.setitem(sys.modules, "bpy", None)  # import bpy -> ImportError
    with pytest.raises(MissingDependencyError, match=r"pip install 'spectrinsic\[blender\]'"):
        load_blend(tmp_path / "any.blend")


@pytest.mark.blender
def test_render_routes_a_blend_file_to_the_importer(blend_file, tmp_path, capsys):
    """``spectrinsic render x.blend`` reads it with the importer (not as YAML): here the
    importer's own one-line error for the material named after no spectrum (its base colour
    not read: ``--no-colours-from-asset``)."""
    from spectrinsic.cli import main

    path, _ = blend_file
    args = ["-q", "render", str(path), "--modes", "rgb3", "--no-colours-from-asset"]
    rc = main([*args, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1
    assert str(path) in err and "'Paint'" in err and "UnicodeDecodeError" not in err
    assert not (tmp_path / "o").exists()
