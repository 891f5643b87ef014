"""One --out rule for every writing verb, and the advisory lock that keeps two runs apart
(issue 17, items 3 and 4). The lock is tested with a second process holding it."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from spectrinsic.cli import main
from spectrinsic.errors import DatasetError, FolderLockedError
from spectrinsic.gt_export import remove_owned_temporaries
from spectrinsic.gt_export.folders.build_folder import check_build_folder, write_marker
from spectrinsic.gt_export.folders.outfolder import (
    LOCK_NAME,
    OUTPUT_MARKER,
    check_out_folder,
    check_output_folder,
    folder_lock,
    output_folder,
)
from tests.conftest import TINY_BUILD
from tests.gt_export.folders._holder import held_lock

#: Longest wait for the helper process to take the lock, seconds.


def _marker(out: Path) -> dict:
    return json.loads((out / OUTPUT_MARKER).read_text())


def test_an_output_folder_records_what_it_wrote_and_accepts_itself_again(tmp_path):
    out = tmp_path / "results"
    with output_folder(out):
        (out / "a.csv").write_text("x")
        (out / "figures").mkdir()
        (out / "figures" / "b.png").write_bytes(b"png")
        assert _marker(out)["writing"]["pid"] == os.getpid()  # says a run is writing
    assert _marker(out) == {
        "spectrinsic_output": 1,
        "files": ["a.csv", "figures/b.png"],
        "writing": None,
    }
    assert not (out / LOCK_NAME).exists()
    check_output_folder(out)  # its own folder: a second run may write again
    with output_folder(out):
        (out / "c.json").write_text("{}")
    assert _marker(out)["files"] == ["a.csv", "c.json", "figures/b.png"]


def test_a_users_file_in_an_own_folder_stops_the_next_run_and_is_kept(tmp_path):
    out = tmp_path / "results"
    with output_folder(out):
        (out / "a.csv").write_text("x")
    (out / "figures").mkdir()
    (out / "figures" / "mine.txt").write_text("mine")
    with pytest.raises(DatasetError, match="figures/mine.txt"):
        check_output_folder(out)
    assert (out / "figures" / "mine.txt").read_text() == "mine"


def test_files_written_before_an_interrupt_are_recorded(tmp_path):
    out = tmp_path / "results"
    with pytest.raises(KeyboardInterrupt), output_folder(out):
        (out / "half.csv").write_text("x")
        raise KeyboardInterrupt
    assert _marker(out)["files"] == ["half.csv"] and _marker(out)["writing"] is None
    check_output_folder(out)


def test_nested_own_folders_are_not_foreign(tmp_path):
    """``study --out results`` beside ``evaluate --out results/evaluation``."""
    with output_folder(tmp_path / "results" / "evaluation"):
        (tmp_path / "results" / "evaluation" / "scores.csv").write_text("x")
    with output_folder(tmp_path / "results"):
        (tmp_path / "results" / "photometric.json").write_text("{}")
    assert _marker(tmp_path / "results")["files"] == ["photometric.json"]


def test_a_refused_run_under_the_lock_leaves_no_folder(tmp_path):
    with pytest.raises(RuntimeError), folder_lock(tmp_path / "a" / "b"):
        raise RuntimeError("refused")
    assert list(tmp_path.iterdir()) == []


def test_a_second_process_is_refused_with_the_holders_pid_host_and_start(tmp_path):
    folder = tmp_path / "ds"
    with held_lock(folder) as proc:
        with pytest.raises(FolderLockedError) as info, folder_lock(folder):
            pass
        message = str(info.value)
        assert f"pid {proc.pid} on " in message and "started 20" in message and "UTC" in message
    with folder_lock(folder):  # released when the holder ended
        pass


@pytest.mark.parametrize("verb", ["dataset", "export", "render", "study"])
def test_every_writing_verb_refuses_a_held_folder_in_one_line_before_any_work(
    tmp_path, capsys, verb
):
    out = tmp_path / "out"
    with held_lock(out) as proc:
        argv = {
            "dataset": ["dataset", *TINY_BUILD, "--only", "obj-apple__v0__white"],
            "export": ["export", str(_dataset(tmp_path))],
            "render": ["render", "obj-apple", "--width", "16", "--height", "16"],
            "study": ["study", "reconstruction-error"],
        }[verb]
        rc = main(["-q", *argv, "--out", str(out)])
        err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert "in use by another spectrinsic run" in err and f"pid {proc.pid}" in err
    assert (
        not out.exists()
    )  # the holder removed its lock file and folder; the refused run made nothing


def _dataset(tmp: Path) -> Path:
    """A folder export takes as a dataset (a manifest) without any sample."""
    root = tmp / "ds"
    root.mkdir()
    (root / "manifest.json").write_text(json.dumps({"format_version": 1, "config_hash": "h"}))
    return root


def test_a_write_probe_left_by_a_killed_run_does_not_block_the_next(tmp_path):
    """A run killed (kill -9) between making and removing its write probe leaves an empty
    ``.spectrinsic-tmp-probe-<pid>`` folder in ``--out``: the folder still counts as new for
    every verb and for a build (seen in the hard-kill test, whose re-run was refused). A
    probe-named folder holding anything is not spectrinsic's probe and keeps the folder foreign."""
    out = tmp_path / "ds"
    probe = out / ".spectrinsic-tmp-probe-4242"
    probe.mkdir(parents=True)
    check_output_folder(out)
    assert check_build_folder(out, "h" * 64, rebuild=False) is None
    write_marker(out, "h" * 64)  # what a build does first; its clean-up then takes the probe
    assert probe in remove_owned_temporaries(out) and not probe.exists()
    other = tmp_path / "other"
    (other / ".spectrinsic-tmp-probe-4242").mkdir(parents=True)
    (other / ".spectrinsic-tmp-probe-4242" / "mine.txt").write_text("mine")
    with pytest.raises(DatasetError, match="not empty"):
        check_build_folder(other, "h" * 64, rebuild=False)
    assert (other / ".spectrinsic-tmp-probe-4242" / "mine.txt").read_text() == "mine"


def test_a_dataset_given_as_another_verbs_out_is_called_a_dataset(tmp_path):
    """``evaluate --out data/dataset`` said the dataset "holds files spectrinsic did not write"
    (task r5-probe2): it is spectrinsic's, but not the kind of folder that verb writes."""
    (tmp_path / ".spectrinsic-dataset").write_text(json.dumps({"spectrinsic_dataset": 1}))
    (tmp_path / "a-sample").mkdir()
    with pytest.raises(
        DatasetError, match="is a spectrinsic dataset, not a train folder; "
    ) as info:
        check_out_folder(tmp_path, own=lambda _: False, what="a train folder")
    assert "did not write" not in str(info.value)
    (tmp_path / ".spectrinsic-dataset").unlink()  # a user's folder: as before
    with pytest.raises(DatasetError, match="holds files spectrinsic did not write"):
        check_out_folder(tmp_path, own=lambda _: False, what="a train folder")
