"""glTF base colours become rgb: reflectances (issue 32), by default since issue 41."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from trimesh.visual.material import PBRMaterial

from spectrinsic.errors import SceneError
from spectrinsic.scenes.meshes import load_mesh_scene
from spectrinsic.spectra import get_spectrum


def test_base_colour_factors_become_rgb_spectra_unless_mapped(tmp_path):
    import colour

    scene = trimesh.Scene()
    for name, offset, rgba in (
        ("brick", -1.0, [200, 60, 40, 255]),
        ("sky", 1.0, [40, 90, 220, 255]),
    ):
        box = trimesh.creation.box((1.0, 1.0, 1.0))
        box.apply_translation((offset, 0.0, 0.5))
        box.visual = trimesh.visual.TextureVisuals(
            material=PBRMaterial(name=name, baseColorFactor=rgba)
        )
        scene.add_geometry(box, name)
    path = tmp_path / "two.glb"
    scene.export(path)
    # without the file's colours an unmapped material is refused, naming the ways to map it
    with pytest.raises(SceneError, match="material 'brick' is not in the material map") as info:
        load_mesh_scene(
            path, materials={"sky": "flat:0.5"}, width=8, height=8, colours_from_asset=False
        )
    for option in ("--material-map", "--default-spectrum", "--colours-from-asset"):
        assert option in str(info.value)
    loaded = load_mesh_scene(path, materials={"sky": "flat:0.5"}, width=8, height=8)
    spectra = {m.spectrum for m in loaded.materials}
    assert "flat:0.5" in spectra  # the map wins over the file's colour
    (brick,) = spectra - {"flat:0.5"}
    assert brick.startswith("rgb:")
    s = get_spectrum(brick)
    sd = colour.SpectralDistribution(dict(zip(s.wavelengths, s.values)))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(sd.shape)
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(sd.shape)
    rgb = colour.XYZ_to_RGB(colour.sd_to_XYZ(sd, cmfs, d65) / 100, "sRGB")
    np.testing.assert_allclose(rgb, np.array([200, 60, 40]) / 255, atol=1e-3)


def test_render_takes_gltf_colours_unless_turned_off(tmp_path, capsys):
    """``render x.glb --no-colours-from-asset`` refuses an unmapped material in one line; by
    default it renders in its base colour."""
    from spectrinsic.cli import main

    box = trimesh.creation.box((1.0, 1.0, 1.0))
    box.visual = trimesh.visual.TextureVisuals(
        material=PBRMaterial(name="brick", baseColorFactor=[200, 60, 40, 255])
    )
    path = tmp_path / "one.glb"
    trimesh.Scene({"brick": box}).export(path)
    args = ["-q", "render", str(path), "--modes", "rgb3", "--spp", "2", "--resolution", "8x8"]
    assert main([*args, "--out", str(tmp_path / "a"), "--no-colours-from-asset"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "'brick'" in err and not (tmp_path / "a").exists()
    assert main([*args, "--out", str(tmp_path / "b")]) == 0
