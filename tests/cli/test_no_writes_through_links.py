"""Issue 36, cause 1: no output is written through a symbolic link inside ``--out``.

A rerun of ``render`` over a ``meta.json`` replaced by a link to a file outside the folder wrote
the render's metadata into that file (rc 0); the same for a dataset rerun (``DATASET.md``,
``index.html``, ``gallery.js``, a ``gallery-pixels/`` folder link), an evaluate rerun
(``REPORT.md``, ``scores.csv``) and a study rerun. Now a folder a run writes into that holds a
link, to a file or a folder, at any depth, is refused in one line before any work (rc 2), and
the file outside is untouched.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from spectrinsic.cli import main
from spectrinsic.gt_export.folders.outfolder import output_folder
from tests.conftest import QUAD_YAML, TINY_BUILD

MINE = "the user's own words\n"


def _outside(tmp_path: Path) -> Path:
    mine = tmp_path / "mine.txt"
    mine.write_text(MINE)
    return mine


def _plant(link: Path, target: Path) -> None:
    """Replace *link* (a file or folder spectrinsic wrote) by a symbolic link to *target*."""
    if link.is_dir():
        for p in sorted(link.iterdir()):
            p.unlink()
        link.rmdir()
    elif link.exists():
        link.unlink()
    link.symlink_to(target)


def _refused(rc: int, capsys, name: str) -> None:
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert err.count("\n") == 0 and "symbolic link" in err and name in err, err


def test_render_rerun_over_a_linked_meta_json_is_refused(tmp_path, capsys):
    scene = tmp_path / "s.yaml"
    scene.write_text(QUAD_YAML)
    out = tmp_path / "r"
    argv = ["-q", "render", str(scene), "--spp", "2", "--out", str(out)]
    assert main(argv) == 0, capsys.readouterr().err
    mine = _outside(tmp_path)
    _plant(out / "meta.json", mine)
    _refused(main(argv), capsys, "meta.json")
    assert mine.read_text() == MINE


@pytest.fixture(scope="module")
def dataset(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("links")
    (root / "s.yaml").write_text(QUAD_YAML)
    assert main(_dataset_argv(root / "ds")) == 0
    return root / "ds"


def _dataset_argv(out: Path) -> list[str]:
    return ["-q", "dataset", *TINY_BUILD, "--scenes", str(out.parent / "s.yaml"), "--out", str(out)]


@pytest.mark.parametrize("name", ["DATASET.md", "index.html", "gallery.js", "gallery-pixels"])
def test_dataset_rerun_over_a_linked_file_or_folder_is_refused(dataset, name, tmp_path, capsys):
    root = Path(shutil.copytree(dataset, tmp_path / "ds"))
    (tmp_path / "s.yaml").write_text(QUAD_YAML)
    assert (root / name).exists(), f"the dataset build no longer writes {name}"
    target = _outside(tmp_path)
    if (root / name).is_dir():
        target = tmp_path / "my-folder"
        target.mkdir()
    _plant(root / name, target)
    _refused(main(_dataset_argv(root)), capsys, name)
    if target.is_dir():
        assert not any(target.iterdir())
    else:
        assert target.read_text() == MINE


def _earlier_output(out: Path, name: str) -> None:
    """An output folder as an earlier evaluate/study run leaves it, *name* among its files."""
    with output_folder(out):
        (out / name).write_text("written by spectrinsic\n")


@pytest.mark.parametrize("name", ["REPORT.md", "scores.csv"])
def test_evaluate_rerun_over_a_linked_file_is_refused(dataset, name, tmp_path, capsys):
    root = dataset
    out = tmp_path / "eval"
    _earlier_output(out, name)
    mine = _outside(tmp_path)
    _plant(out / name, mine)
    _refused(main(["-q", "evaluate", "--dataset", str(root), "--out", str(out)]), capsys, name)
    assert mine.read_text() == MINE


def test_study_rerun_over_a_linked_file_is_refused(tmp_path, capsys):
    out = tmp_path / "study"
    _earlier_output(out, "photometric.json")
    mine = _outside(tmp_path)
    _plant(out / "photometric.json", mine)
    _refused(main(["-q", "study", "photometric", "--out", str(out)]), capsys, "photometric.json")
    assert mine.read_text() == MINE
