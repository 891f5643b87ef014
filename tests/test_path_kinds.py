"""What a path is, in words (spectrinsic.path_kinds): a folder option given a file is told so,
not "does not exist" (task r5-probe2)."""

from __future__ import annotations

import os

import pytest

from spectrinsic.path_kinds import file_type, folder_problem


def test_file_type_names_a_file_a_folder_and_a_fifo(tmp_path):
    (tmp_path / "f.txt").write_text("x")
    assert file_type(tmp_path / "f.txt") == "a file"
    assert file_type(tmp_path) == "a folder"
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs on this platform")
    os.mkfifo(tmp_path / "pipe")
    assert file_type(tmp_path / "pipe") == "a FIFO (named pipe)"


def test_folder_problem_is_none_only_for_a_folder(tmp_path):
    (tmp_path / "f.txt").write_text("x")
    (tmp_path / "link").symlink_to(tmp_path)  # followed, as opening it would
    assert folder_problem(tmp_path) is None and folder_problem(tmp_path / "link") is None
    assert folder_problem(tmp_path / "f.txt") == "is a file, not a folder"
    assert folder_problem(tmp_path / "gone") == "does not exist"
