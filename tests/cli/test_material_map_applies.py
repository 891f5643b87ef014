"""``--material-map`` and ``--default-spectrum`` apply to .blend and mesh files only; given for
a YAML or Mitsuba XML scene (which states every material's spectrum) they are refused in one
line before any work (task r5-probe: ``render quad.yaml --material-map m.yaml`` rendered and
ignored the map)."""

from __future__ import annotations

import pytest

from spectrinsic.cli import main
from spectrinsic.scenes.sources import takes_material_map
from tests.conftest import QUAD_YAML, one_line_error

OPTIONS = {"--material-map": "map.yaml", "--default-spectrum": "flat:0.5"}


@pytest.mark.parametrize("option", OPTIONS)
@pytest.mark.parametrize("verb", ["render", "dataset"])
def test_refused_for_a_yaml_scene(tmp_path, capsys, option, verb):
    (tmp_path / "quad.yaml").write_text(QUAD_YAML)
    (tmp_path / "map.yaml").write_text("grey: flat:0.5\n")
    value = str(tmp_path / OPTIONS[option])
    scene = str(tmp_path / "quad.yaml")
    where = [scene] if verb == "render" else ["--scenes", scene]
    out = tmp_path / "out"
    argv = [verb, *where, option, value if option == "--material-map" else OPTIONS[option]]
    assert main([*argv, "--out", str(out)]) == 2
    one_line_error(capsys, option, ".blend and mesh files")
    assert not out.exists()


def test_which_files_take_a_material_map(tmp_path):
    """By kind: meshes and .blend files name their materials only."""
    names = ("a.obj", "a.glb", "a.ply", "a.blend", "a.yaml", "a.xml")
    assert [takes_material_map(tmp_path / n) for n in names] == [True] * 4 + [False] * 2
