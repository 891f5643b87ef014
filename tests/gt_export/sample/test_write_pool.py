"""A sample's files written by threads (issue 45): the same bytes, the serial writer's errors."""

from __future__ import annotations

import errno
import hashlib
import threading

import pytest

from spectrinsic.errors import DiskFullError
from spectrinsic.file_writes import replacing
from spectrinsic.gt_export import export_sample
from spectrinsic.gt_export.formats import png
from spectrinsic.gt_export.sample import write_pool
from spectrinsic.gt_export.sample.write_pool import FileWrites


def _text(content: str):
    def write(path):
        with replacing(path) as tmp:
            tmp.write_text(content)

    return write


def _fails(message: str, after: threading.Event | None = None):
    def write(path):
        if after is not None:
            assert after.wait(10)
        raise OSError(message)

    return write


def test_the_hashes_are_those_of_the_written_files(tmp_path):
    with FileWrites(tmp_path) as writes:
        for name in ("a.txt", "b.txt", "c.txt"):
            writes.submit(name, _text(name * 1000))
        hashes = writes.hashes()
    assert list(hashes) == ["a.txt", "b.txt", "c.txt"]  # the order they were handed over
    for name, digest in hashes.items():
        assert digest == hashlib.sha256((name * 1000).encode()).hexdigest()


def test_the_first_failure_handed_over_is_raised_whichever_ends_first(tmp_path):
    """b fails only after c has failed: b's error is raised, as a serial writer raises it."""
    c_failed = threading.Event()

    def c_fails(path):
        try:
            raise OSError("c")
        finally:
            c_failed.set()

    with pytest.raises(OSError, match="^b$"), FileWrites(tmp_path) as writes:
        writes.submit("a.txt", _text("a"))
        writes.submit("b.txt", _fails("b", after=c_failed))
        writes.submit("c.txt", c_fails)
        writes.hashes()


def test_an_error_computed_after_a_failed_write_yields_to_it(tmp_path):
    with pytest.raises(OSError, match="^write$"), FileWrites(tmp_path) as writes:
        writes.submit("a.txt", _fails("write"))
        raise ValueError("computed after the write: a serial writer never gets here")


def test_every_write_has_ended_when_the_block_ends(tmp_path):
    """After an error in the block, no thread still writes into the folder the caller removes."""
    started, release = threading.Event(), threading.Event()

    def slow(path):
        started.set()
        assert release.wait(10)
        _text("late")(path)

    with pytest.raises(KeyError), FileWrites(tmp_path, threads=1) as writes:
        writes.submit("slow.txt", slow)
        writes.submit("never.txt", _text("never"))  # queued behind slow: dropped
        assert started.wait(10)
        threading.Timer(0.2, release.set).start()
        raise KeyError("the main thread fails while slow.txt is being written")
    assert (tmp_path / "slow.txt").read_text() == "late"  # waited for, not abandoned
    assert not (tmp_path / "never.txt").exists()


def test_without_threads_each_file_is_written_at_once(tmp_path):
    with FileWrites(tmp_path, threads=0) as writes:
        writes.submit("a.txt", _text("a"))
        assert (tmp_path / "a.txt").read_text() == "a"
        with pytest.raises(OSError, match="now"):
            writes.submit("b.txt", _fails("now"))


def _files(folder):
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def test_threaded_and_serial_writers_write_the_same_bytes(
    tmp_path, two_light_sample, config, monkeypatch
):
    """Every file of a sample, meta.json included, is byte for byte the serial writer's."""
    scene, result = two_light_sample
    threaded = export_sample(tmp_path / "a", scene, result, sample_id="s", config=config, seed=3)
    monkeypatch.setattr(write_pool, "WRITE_THREADS", 0)
    serial = export_sample(tmp_path / "b", scene, result, sample_id="s", config=config, seed=3)
    files = _files(threaded)
    assert len(files) > 10 and "meta.json" in files and "previews/image.png" in files
    assert files == _files(serial)


def test_a_full_disk_in_a_write_thread_is_one_line_naming_the_samples_file(
    tmp_path, one_light_sample, config, monkeypatch
):
    scene, result = one_light_sample

    def full(path, rgb8):
        with replacing(path):
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(png, "write_png", full)
    with pytest.raises(DiskFullError) as caught:
        export_sample(tmp_path, scene, result, sample_id="s", config=config, seed=1)
    message = str(caught.value)
    assert "\n" not in message and str(tmp_path / "s" / "previews") in message
    assert list(tmp_path.iterdir()) == []  # no sample, no temporary folder
