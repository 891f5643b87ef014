"""Issue 36, cause 5: numbers checked in the precision they are used in.

A scene light of power 1e+38 or 1e+300 gave Inf/NaN raw passes (after a numpy overflow warning
in the float32 cast), and a vertex of 1e300 (finite in float64, infinite in float32) reached
Mitsuba. Powers are bounded to :data:`~spectrinsic.scenes.validate.POWER_RANGE` and coordinates
to :data:`~spectrinsic.scenes.validate.MAX_COORDINATE`, each refused in one line naming the
field, before any render.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.cli import main

SCENE = """\
name: quad
materials: {grey: "flat:0.5"}
meshes:
  - name: ground
    vertices: [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [VERTEX, 2, 0]]
    faces: [[0, 1, 2], [0, 2, 3]]
    material: grey
lights:
  - {kind: point, spectrum: "cie:D65", power: POWER, position: [0, 0, POSITION]}
camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 16, height: 16}
"""


def _render(tmp_path, capsys, power="4", vertex="-2", position="2") -> tuple[int, str]:
    path = tmp_path / "scene.yaml"
    text = SCENE.replace("POWER", power).replace("VERTEX", vertex)
    path.write_text(text.replace("POSITION", position))
    rc = main(["render", str(path), "--out", str(tmp_path / "out"), "--modes", "rgb3"])
    return rc, capsys.readouterr().err.strip()


@pytest.mark.parametrize("power", ["1.0e+38", "1.0e+300", "1.0e+21"])
def test_a_light_power_beyond_float32_rendering_is_refused(tmp_path, capsys, power):
    rc, err = _render(tmp_path, capsys, power=power)
    assert rc == 2 and "\n" not in err
    assert "lights[0].power" in err and "[1e-20, 1e+20]" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("vertex", ["-1.0e+300", "-1.0e+19"])
def test_a_vertex_infinite_in_float32_is_refused(tmp_path, capsys, vertex):
    rc, err = _render(tmp_path, capsys, vertex=vertex)
    assert rc == 2 and "\n" not in err
    assert "meshes[0] ('ground').vertices" in err and "first: vertex 3" in err


def test_a_light_position_beyond_the_coordinate_bound_is_refused(tmp_path, capsys):
    rc, err = _render(tmp_path, capsys, position="1.0e+300")
    assert rc == 2 and "\n" not in err and "lights[0].position" in err


def test_the_bounds_keep_what_float32_can_carry():
    from spectrinsic.scenes.validate import MAX_COORDINATE, POWER_RANGE

    lo, hi = POWER_RANGE
    # power x a spectrum's peak (<~1e3 after unit-luminance scaling) stays a float32 normal
    assert np.isfinite(np.float32(hi * 1e3)) and np.float32(lo / 1e3) > np.finfo(np.float32).tiny
    # a squared distance between two coordinates stays finite in float32
    assert np.isfinite(np.float32(2 * MAX_COORDINATE) ** 2)
