"""Inputs that would make every sample fail are refused before the build, in one line, and
leave no ``--out``: a camera CSV that is not three sensor curves, and a glossy or textured
scene file rendered with ``--integrator passes`` (each gave a failed sample, rc 1 and half a
dataset)."""

from __future__ import annotations

import pytest

from spectrinsic.cli import main

LIGHT = "lights:\n  - {kind: point, spectrum: 'cie:D65', power: 4, position: [0, 0, 2]}\n"
CAMERA = "camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 8, height: 8}\n"
QUAD = "  - {name: q, vertices: [[-1,-1,0],[1,-1,0],[1,1,0]], faces: [[0,1,2]], material: m}\n"
MATERIALS = {
    "glossy": "m: {kind: plastic, spectrum: 'flat:0.5', roughness: 0.1}",
    "textured": "m: {kind: textured, pattern: noise, size: 8, seed: 1, basis: ['flat:0.2', 'flat:0.8']}",
}


def _dataset(tmp_path, capsys, *options: str) -> tuple[int, str]:
    rc = main(["-q", "dataset", "--out", str(tmp_path / "o"), *options])
    return rc, capsys.readouterr().err.strip()


@pytest.mark.parametrize(
    "csv, problem",
    [
        ("wavelength [nm],a [1],b [1]\n380,0.1,0.2\n780,0.1,0.2\n", "expected three"),
        ("wavelength [nm],r [1],g [1],b [1]\n380,0.1,0.2,0\n780,0.1,0.2,0\n", "no response"),
    ],
)
def test_a_camera_csv_that_is_not_three_live_curves_is_refused(tmp_path, capsys, csv, problem):
    (tmp_path / "cam.csv").write_text(csv)
    rc, err = _dataset(
        tmp_path, capsys, "--camera", f"csv:{tmp_path / 'cam.csv'}"
    )  # default preset
    assert rc == 2 and "\n" not in err and problem in err and "cam.csv" in err, err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("kind", sorted(MATERIALS))
def test_a_scene_file_the_passes_integrator_cannot_render_is_refused(tmp_path, capsys, kind):
    scene = tmp_path / f"{kind}.yaml"
    scene.write_text(f"name: s\nmaterials:\n  {MATERIALS[kind]}\nmeshes:\n{QUAD}{LIGHT}{CAMERA}")
    rc, err = _dataset(
        tmp_path, capsys, "--preset", "preview", "--scenes", str(scene), "--integrator", "passes"
    )
    assert rc == 2 and "\n" not in err and f"{kind}.yaml" in err and "passes" in err, err
    assert not (tmp_path / "o").exists()
