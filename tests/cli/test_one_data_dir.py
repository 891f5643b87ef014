"""Issue 36, cause 15: one data directory per run, for every verb and every worker.

The global ``--data-dir`` was ignored by ``relight`` ("needs a spectral data directory"; with
``SPECTRINSIC_DATA`` also set, relight silently used that one instead) and by ``dataset``'s
samples (``--generator objects-on-ground --sfu`` passed its pre-check, then every sample failed;
``--scenes`` with an ``sfu:`` material wrote the sample, then ended rc 2). Now the option, else
the environment, is resolved once and used by the whole run. Each test runs with no
``SPECTRINSIC_DATA`` (or with one pointing at an empty folder, which must not be used).
"""

from __future__ import annotations

import os

import pytest

from spectrinsic.cli import main
from spectrinsic.render import RenderSettings
from tests.conftest import TINY_BUILD
from tests.gt_export._builders import render_transport_sample

SCENE = """\
name: quad
materials: {sfu: "sfu:munsell/17"}
meshes:
  - name: ground
    vertices: [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]
    faces: [[0, 1, 2], [0, 2, 3]]
    material: sfu
lights:
  - {kind: point, spectrum: "sfu-illum:mws_000", power: 4, position: [0, 0, 2]}
camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 16, height: 16}
"""


@pytest.fixture(params=["unset", "elsewhere"])
def environment(request, monkeypatch, tmp_path) -> None:
    """No $SPECTRINSIC_DATA, or one naming an empty folder (the option must win)."""
    if request.param == "unset":
        monkeypatch.delenv("SPECTRINSIC_DATA", raising=False)
    else:
        (tmp_path / "empty-data").mkdir()
        monkeypatch.setenv("SPECTRINSIC_DATA", str(tmp_path / "empty-data"))


def _ok(rc: int, capsys) -> None:
    err = capsys.readouterr().err
    assert rc == 0, err


def test_relight_uses_the_global_data_dir(data_dir, environment, tmp_path, make_room, capsys):
    scene = make_room(size=8)
    settings = RenderSettings(spp=2, modes=("rgb3",), batches=2, max_depth=3)
    sample, _, _ = render_transport_sample(
        tmp_path / "src", scene, settings, seed=3, sample_id="room__v0__two", config={"t": 36}
    )
    out = tmp_path / "relit"
    argv = ["-q", "--data-dir", str(data_dir), "relight", str(sample)]
    rc = main([*argv, "--light", "0=sfu-illum:mws_000", "--out", str(out)])
    _ok(rc, capsys)
    assert (out / "meta.json").is_file()


def test_dataset_generator_samples_use_the_global_data_dir(data_dir, environment, tmp_path, capsys):
    out = tmp_path / "ds"
    argv = [
        "-q",
        "--data-dir",
        str(data_dir),
        "dataset",
        *TINY_BUILD,
        "--generator",
        "objects-on-ground",
    ]
    rc = main([*argv, "--count", "1", "--sfu", "--out", str(out)])
    _ok(rc, capsys)
    assert len([p for p in out.rglob("meta.json")]) == 1


def test_dataset_scene_file_with_sfu_spectra_uses_the_global_data_dir(
    data_dir, environment, tmp_path, capsys
):
    scene = tmp_path / "scene.yaml"
    scene.write_text(SCENE)
    out = tmp_path / "ds"
    rc = main(["-q", "--data-dir", str(data_dir), "dataset", *TINY_BUILD, "--scenes", str(scene),
               "--out", str(out)])  # fmt: skip
    _ok(rc, capsys)
    assert len([p for p in out.rglob("meta.json")]) == 1


def test_render_uses_the_global_data_dir(data_dir, environment, tmp_path, capsys):
    scene = tmp_path / "scene.yaml"
    scene.write_text(SCENE)
    out = tmp_path / "r"
    rc = main(["-q", "--data-dir", str(data_dir), "render", str(scene), "--out", str(out)])
    _ok(rc, capsys)
    assert (out / "meta.json").is_file()


def test_the_run_leaves_the_environment_as_it_found_it(tmp_path, monkeypatch):
    """The run's directory is visible to its workers while it lasts, not after it."""
    from spectrinsic.data_dir import one_data_dir

    (tmp_path / "mine").mkdir()
    monkeypatch.setenv("SPECTRINSIC_DATA", str(tmp_path / "theirs-missing"))
    with one_data_dir(tmp_path / "mine") as chosen:
        assert chosen == str((tmp_path / "mine").resolve())
        assert os.environ["SPECTRINSIC_DATA"] == chosen
    assert os.environ["SPECTRINSIC_DATA"] == str(tmp_path / "theirs-missing")
    with one_data_dir(None) as chosen:  # a wrong environment is refused where it is read
        assert chosen is None
