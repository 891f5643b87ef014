"""Inputs that once printed numpy ``RuntimeWarning``s before a correct result or refusal now
print the refusal alone, in one line, or nothing beside the result (issue 44, cause 12).

Each case runs the command line in its own process, as a user would: an in-process run would
let pytest capture the warnings instead of showing what a user sees on stderr. A 1e308
spectrum is normalised before its sums; ``translate x=1e400`` (infinity to float), a zero-scaled
area emitter and a PLY vertex of NaN are refused before any arithmetic on them. ``relight
--power 1e20``: ``tests/gt_export/test_relight_csv_and_warnings.py``.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import spectrinsic

ROOT = Path(spectrinsic.__file__).parents[1]  # the package under test, wherever tests lie
XML = """<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
  </sensor>
  <emitter type="point"><point name="position" x="0" y="0" z="3"/><rgb name="intensity" value="5"/></emitter>
  <shape type="rectangle"><bsdf type="diffuse"/>{extra}</shape>
</scene>
"""
YAML = """name: big
materials:
  m: {spectrum: 'flat:0.5'}
meshes:
  - {name: q, vertices: [[-1,-1,0],[1,-1,0],[1,1,0],[-1,1,0]], faces: [[0,1,2],[0,2,3]], material: m}
lights:
  - {kind: point, spectrum: 'csv:big.csv#lamp [W/m2/nm]', power: 4, position: [0, 0, 2]}
camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 8, height: 8}
"""
PLY = (
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\nnan 1 0\n1 0 0\n3 0 1 2\n"
)
ZERO_EMITTER = (
    '</shape><shape type="rectangle"><transform name="to_world"><scale value="0"/>'
    '<translate z="2"/></transform><emitter type="area"><rgb name="radiance" value="5"/>'
    "</emitter>"
)


def _spectrinsic(folder: Path, *args: str) -> tuple[int, str, str]:
    proc = subprocess.run(
        [sys.executable, "-P", "-m", "spectrinsic", *args],
        capture_output=True,
        text=True,
        check=False,
        cwd=folder,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        timeout=300,
    )
    return proc.returncode, proc.stdout, proc.stderr


def _render(folder: Path, scene: str, *options: str) -> tuple[int, str, str]:
    out = ["--modes", "rgb3", "--spp", "2", "--out", "o"]
    return _spectrinsic(folder, "render", scene, *out, *options)


@pytest.mark.parametrize(
    ("name", "write", "options", "refusal"),
    [
        (
            "far.xml",
            lambda d: (d / "far.xml").write_text(
                XML.format(extra='<transform name="to_world"><translate x="1e400"/></transform>')
            ),
            (),
            "to_world transform holds a non-finite number",
        ),
        (
            "zero.xml",
            lambda d: (d / "zero.xml").write_text(XML.format(extra=ZERO_EMITTER)),
            (),
            "an area emitter on a rectangle of zero area",
        ),
        (
            "nan.ply",
            lambda d: (d / "nan.ply").write_text(PLY),
            ("--default-spectrum", "flat:0.5"),
            "1 vertices are NaN or infinite",
        ),
    ],
    ids=["translate-1e400", "zero-scaled-emitter", "ply-nan-vertex"],
)
def test_a_bad_number_is_refused_in_one_line_without_warnings(
    tmp_path, name, write, options, refusal
):
    write(tmp_path)
    rc, out, err = _render(tmp_path, name, *options)
    assert rc == 2 and out == "", (out, err)
    assert len(err.splitlines()) == 1 and refusal in err and name in err, err
    assert "Warning" not in err and not (tmp_path / "o").exists()


def test_a_1e308_spectrum_renders_without_warnings(tmp_path):
    """The spectrum's shape is what counts (illuminants are normalised): it renders, and with
    -q nothing but the result (stdout) is printed."""
    (tmp_path / "big.csv").write_text(
        "wavelength [nm],lamp [W/m2/nm]\n380,1e308\n550,1e308\n780,1e308\n"
    )
    (tmp_path / "big.yaml").write_text(YAML)
    rc, out, err = _render(tmp_path, "big.yaml", "-q")
    assert rc == 0 and err == "", err
    assert "Warning" not in out and (tmp_path / "o" / "rgb3.exr").is_file()
