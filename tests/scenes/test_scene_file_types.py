"""A scene path that is not a regular file (a FIFO, a folder) is refused in one line before it
is opened, for every format: a FIFO named ``scene.yaml`` hung ``render`` forever."""

from __future__ import annotations

import os
import signal

import pytest

from spectrinsic.cli import main

#: Seconds a refusal may take before the test calls it a hang.
HANG_S = 20


@pytest.fixture
def no_hang():
    def hung(signum, frame):
        raise AssertionError(f"still reading after {HANG_S} s: the FIFO was opened")

    old = signal.signal(signal.SIGALRM, hung)
    signal.alarm(HANG_S)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


@pytest.mark.parametrize("name", ["scene.yaml", "scene.ply", "scene.glb", "scene.blend", "noext"])
def test_a_fifo_as_scene_file_is_refused_in_one_line(tmp_path, capsys, no_hang, name):
    fifo = tmp_path / name
    os.mkfifo(fifo)
    rc = main(["-q", "render", str(fifo), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "\n" not in err and "FIFO" in err and name in err, err
    assert not (tmp_path / "o").exists()


def test_a_folder_as_scene_file_is_refused_in_one_line(tmp_path, capsys):
    (tmp_path / "scene.yaml").mkdir()
    rc = main(["-q", "render", str(tmp_path / "scene.yaml"), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "\n" not in err and "a folder" in err, err
