"""A new researcher's first mistakes (task r5-probe2): a mistyped verb, option or choice gets
the closest name; a folder argument given a file, or a folder that holds no dataset, is told
what it is. Each is one line on stderr, status 2."""

from __future__ import annotations

import pytest

from spectrinsic.cli import main


def _one_line(capsys, argv: list[str]) -> str:
    try:
        status = main(argv)
    except SystemExit as exc:  # argparse's own refusals exit from the parser
        status = exc.code
    assert status == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("spectrinsic: error: ")
    return err


@pytest.mark.parametrize(
    "argv, hint",
    [
        (["rendr", "x.yaml"], "(did you mean 'render'?)"),
        (["study", "photometrc"], "(did you mean 'photometric'?)"),
        (["dataset", "--preset", "previw"], "(did you mean 'preview'?)"),
        (
            ["dataset", "--sceens", "a.yaml"],
            "dataset: unrecognized arguments: --sceens a.yaml (did you mean '--scenes'",
        ),
        (["render", "a.yaml", "--out", "o", "--ground-truht"], "(did you mean '--ground-truth'?)"),
    ],
)
def test_a_mistyped_name_gets_the_closest_one(capsys, argv, hint):
    assert hint in _one_line(capsys, argv)


def test_an_unlike_name_gets_no_guess(capsys):
    err = _one_line(capsys, ["info", "--bogus"])
    assert "info: unrecognized arguments: --bogus" in err and "did you mean" not in err


@pytest.mark.parametrize(
    "argv, said",
    [
        (["check", "{f}"], "check '{f}' is a file, not a folder; expected a dataset folder"),
        (["--data-dir", "{f}", "info"], "data directory '{f}' (from --data-dir) is a file, not"),
        (["evaluate", "--dataset", "{f}", "--out", "{d}/ev"], "--dataset '{f}' is a file, not"),
        (["check", "{d}/gone"], "check '{d}/gone' does not exist; expected a dataset folder"),
    ],
)
def test_a_file_where_a_folder_is_expected_is_called_a_file(tmp_path, capsys, argv, said):
    f = tmp_path / "notes.txt"
    f.write_text("x")
    argv = [a.format(f=f, d=tmp_path) for a in argv]
    assert said.format(f=f, d=tmp_path) in _one_line(capsys, argv)
    assert not (tmp_path / "ev").exists()


@pytest.mark.torch
def test_train_on_a_folder_without_a_manifest_says_so(tmp_path, capsys):
    """It said "manifest.json has no splits; rebuild the dataset"."""
    pytest.importorskip("torch", reason="train needs the torch extra (make test-torch)")
    err = _one_line(capsys, ["train", str(tmp_path), "--out", str(tmp_path / "tr")])
    assert "no manifest.json; expected a built dataset folder" in err


@pytest.mark.parametrize(
    "argv, said",
    [
        (["bogus", "--ground-truth"], "unknown library scene 'bogus'; expected one of"),
        (["room-corner", "--view", "7", "--ground-truth"], "view 7 of library scene"),
        (["room-corner", "--condition", "blue", "--ground-truth"], "illumination condition 'blue'"),
        (["", "--ground-truth"], "unknown library scene ''"),  # not "'.' is a folder"
    ],
)
def test_a_library_sample_that_does_not_exist_is_named_as_such(tmp_path, capsys, argv, said):
    """Under --ground-truth it said "--only 'bogus__v0__white' matches no sample", an option
    the user never gave."""
    out = tmp_path / "o"
    err = _one_line(capsys, ["render", *argv, "--out", str(out), "--preset", "preview", "-q"])
    assert said in err and "--only" not in err and not out.exists()


def test_an_empty_scenes_entry_is_not_the_working_folder(tmp_path, capsys):
    err = _one_line(capsys, ["dataset", "--scenes", "", "--out", str(tmp_path / "o"), "-q"])
    assert "--scenes '': an empty path; expected scene files" in err


def test_an_empty_scene_is_no_scene_file(tmp_path, capsys):
    err = _one_line(capsys, ["render", "", "--out", str(tmp_path / "o"), "-q"])
    assert "unknown library scene ''" in err and "is a folder" not in err


@pytest.mark.parametrize(
    "argv, said",
    [
        (["--modes", "rgb3,rgb3"], "--modes 'rgb3,rgb3': rgb3 given twice"),
        (["--modes", "RGB3"], "(did you mean 'rgb3'"),
    ],
)
def test_modes_given_twice_or_in_capitals(tmp_path, capsys, argv, said):
    (tmp_path / "s.yaml").write_text("name: s\n")  # refused before the scene is read
    err = _one_line(
        capsys, ["render", str(tmp_path / "s.yaml"), "--out", str(tmp_path / "o"), *argv]
    )
    assert said in err and not (tmp_path / "o").exists()


def test_an_empty_data_dir_is_not_the_working_folder(capsys):
    err = _one_line(capsys, ["--data-dir", "", "info"])
    assert "data directory '' (from --data-dir): an empty path" in err
