"""Integrity end to end on tiny real samples: corruption is re-rendered rather than resumed,
one config per folder, a killed worker leaves a clean set, a full disk stops the build in one
line, and a build where every sample fails leaves no manifest.

Samples are 16 x 16 at 2 spp (the preview preset shrunk); two objects are built once and copied.
"""

from __future__ import annotations

import errno
import json
import logging
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from spectrinsic.cli import main
from spectrinsic.gt_export import check_dataset, is_complete
from spectrinsic.gt_export.dataset.build_time import (
    BUILD_TIME_NAME,
    read_build_record,
    reproducible_bytes,
)
from spectrinsic.gt_export.sample import TMP_PREFIX
from spectrinsic.pipeline.dataset import build_dataset
from spectrinsic.pipeline.presets import get_preset
from tests.conftest import TINY_BUILD

IDS = ("obj-apple__v0__white", "obj-box__v0__white")
ONLY = ",".join(IDS)
CONFIG = get_preset("preview").with_options(width=16, height=16, spp=2)
CLI = ["-q", "dataset", *TINY_BUILD, "--only", ONLY]
#: How long a subprocess build may take to reach the state a test interrupts.
WAIT_S = 180.0


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("integrity") / "ds"
    report = build_dataset(out, CONFIG, only=ONLY)
    assert report.ok and check_dataset(out) == []
    return out


@pytest.fixture()
def copy(built: Path, tmp_path: Path) -> Path:
    target = tmp_path / "ds"
    shutil.copytree(built, target)
    return target


def _bytes(root: Path) -> dict[str, bytes]:
    return {
        p.relative_to(root).as_posix(): p.read_bytes()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def _timeless_bytes(root: Path) -> dict[str, bytes]:
    """:func:`_bytes` less the build's time: the card's line of it, and ``build-time.json``,
    to which every rerun adds its run."""
    return {
        p.relative_to(root).as_posix(): reproducible_bytes(p)
        for p in sorted(root.rglob("*"))
        if p.is_file() and p.name != BUILD_TIME_NAME
    }


@pytest.mark.parametrize("corrupt", ["other-samples-file", "undecodable-exr", "missing-preview"])
def test_a_corrupt_sample_is_rerendered_not_resumed(copy, built, corrupt, caplog):
    apple = copy / IDS[0]
    if corrupt == "other-samples-file":
        shutil.copyfile(copy / IDS[1] / "geometry.exr", apple / "geometry.exr")
    elif corrupt == "undecodable-exr":
        data = bytearray((apple / "image.exr").read_bytes())
        data[len(data) // 2 :] = b"\0" * (len(data) - len(data) // 2)
        (apple / "image.exr").write_bytes(bytes(data))
    else:
        next((apple / "previews").glob("*.png")).unlink()
    assert check_dataset(copy) != []
    with caplog.at_level(logging.WARNING, logger="spectrinsic.pipeline.dataset"):
        report = build_dataset(copy, CONFIG, only=ONLY)
    assert [o.sample_id for o in report.built] == [IDS[0]]  # re-rendered, and said so
    assert [o.sample_id for o in report.skipped] == [IDS[1]]
    assert any(IDS[0] in r.message and "re-rendering" in r.message for r in caplog.records)
    assert check_dataset(copy) == []
    assert _timeless_bytes(copy) == _timeless_bytes(built)  # the same pixels as before the damage
    record = read_build_record(copy, CONFIG.config_hash())
    assert record is not None and [r.samples_built for r in record.runs] == [2, 1]  # the repair


def test_a_bit_flipped_key_in_meta_json_is_named_then_rerendered(copy, built, capsys, caplog):
    """ "median" -> "mediaN" (one bit): check names the file and the field in one line, and a
    rerun re-renders the sample (it used to raise KeyError in both)."""
    meta = copy / IDS[0] / "meta.json"
    text = meta.read_text(encoding="utf-8")
    assert '"median"' in text
    meta.write_text(text.replace('"median"', '"mediaN"', 1), encoding="utf-8")
    rc = main(["-q", "check", str(copy)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "Traceback" not in err
    assert str(meta) in err and "noise.image.median: missing" in err
    with caplog.at_level(logging.WARNING, logger="spectrinsic.pipeline.dataset"):
        report = build_dataset(copy, CONFIG, only=ONLY)
    assert [o.sample_id for o in report.built] == [IDS[0]]
    assert any(
        IDS[0] in r.message and "median" in r.message and "re-rendering" in r.message
        for r in caplog.records
    )
    assert check_dataset(copy) == []
    assert _timeless_bytes(copy) == _timeless_bytes(built)


def test_an_edited_digit_of_a_fitted_matrix_is_rerendered_not_blessed(copy, built, caplog):
    """One digit of ``matrices`` changed by hand: check fails, a rerun re-renders the sample
    (it used to skip it and write the edited file's hash into manifest.json), check passes."""
    meta = copy / IDS[0] / "meta.json"
    text = meta.read_text(encoding="utf-8")
    start = text.index('"matrices"')
    digit = next(i for i in range(start, len(text)) if text[i] in "123456789")
    meta.write_text(
        text[:digit] + str(int(text[digit]) % 9 + 1) + text[digit + 1 :], encoding="utf-8"
    )
    assert any(
        p.startswith(f"{IDS[0]}: meta.json does not match its seal") for p in check_dataset(copy)
    )
    with caplog.at_level(logging.WARNING, logger="spectrinsic.pipeline.dataset"):
        report = build_dataset(copy, CONFIG, only=ONLY)
    assert [o.sample_id for o in report.built] == [IDS[0]]
    assert any(
        IDS[0] in r.message and "seal" in r.message and "re-rendering" in r.message
        for r in caplog.records
    )
    assert check_dataset(copy) == []
    assert _timeless_bytes(copy) == _timeless_bytes(built)


def test_a_rerun_with_another_config_is_refused_then_rebuilt_with_rebuild(copy, capsys):
    before = _bytes(copy)
    rc = main([*CLI[:-2], "--spp", "4", "--only", IDS[0], "--out", str(copy)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "--rebuild" in err and str(copy) in err
    assert _bytes(copy) == before  # refused before touching anything

    rc = main([*CLI[:-2], "--spp", "4", "--only", IDS[0], "--out", str(copy), "--rebuild"])
    assert rc == 0, capsys.readouterr().err
    spp4 = CONFIG.with_options(spp=4).config_hash()
    manifest = json.loads((copy / "manifest.json").read_text())
    assert manifest["config"]["spp"] == 4 and manifest["config_hash"] == spp4
    for sample_id in IDS:  # the sample outside --only was rebuilt too: one config per folder
        assert is_complete(copy / sample_id, spp4), sample_id
        assert manifest["samples"][sample_id]["config_hash"] == spp4
    assert check_dataset(copy) == []


def test_check_catches_a_sample_of_another_config(copy):
    """A set mixed by hand (one meta.json and its manifest entry claim another config)."""
    meta_path = copy / IDS[0] / "meta.json"
    meta = json.loads(meta_path.read_text())
    meta["config_hash"] = "f" * 64
    meta_path.write_text(json.dumps(meta))
    problems = check_dataset(copy)
    assert any(
        p.startswith(IDS[0]) and "built with config hash ffffffffffff" in p for p in problems
    )


def test_foreign_temporaries_in_a_dataset_are_never_removed(copy):
    (copy / ".tmp-mine").mkdir()
    (copy / ".tmp-mine" / "db").write_text("b")
    (copy / ".spectrinsic-tmp-obj-apple__v0__white-dead").mkdir()  # a crashed write of ours
    report = build_dataset(copy, CONFIG, only=ONLY)
    assert report.ok and not report.built
    assert (copy / ".tmp-mine" / "db").read_text() == "b"
    assert not list(copy.glob(".spectrinsic-tmp-*"))


def test_a_full_disk_stops_the_build_in_one_line_naming_the_file(tmp_path, monkeypatch, capsys):
    import OpenEXR

    class FullDisk:
        def __init__(self, *args, **kwargs):
            pass

        def write(self, path):
            Path(path).write_bytes(b"partial")
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(OpenEXR, "File", FullDisk)
    out = tmp_path / "ds"
    rc = main([*CLI, "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert "No space left on device" in err and ".exr" in err
    assert not list(out.glob(".spectrinsic-tmp-*")) and not (out / "manifest.json").exists()
    assert not any((out / s).exists() for s in IDS)


def test_when_every_sample_fails_failed_lines_and_no_manifest(tmp_path, monkeypatch, capsys):
    import spectrinsic.pipeline.dataset as pipeline_dataset

    def failing(scene, settings, **kwargs):
        raise RuntimeError(f"simulated failure of {scene.name}")

    monkeypatch.setattr(pipeline_dataset, "render_batches", failing)
    out = tmp_path / "ds"
    rc = main([*CLI, "--out", str(out)])
    captured = capsys.readouterr()
    assert rc == 1
    for sample_id in IDS:
        assert f"FAILED {sample_id}: RuntimeError: simulated failure" in captured.out
    assert "no complete sample" in captured.out
    assert not (out / "manifest.json").exists() and not (out / "DATASET.md").exists()


def _parent_pid(pid: str) -> int | None:
    """The parent of process *pid* from ``/proc/<pid>/stat`` (``None`` if it exited)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    # "pid (comm) state ppid ...": comm may hold spaces and parentheses, so split after the last ")"
    return int(stat[stat.rindex(")") + 2 :].split()[1])


def _workers(pid: int) -> list[int]:
    """Pool workers (spawned children running ``spawn_main``) of process *pid*.

    Found by each process's parent in ``/proc/<pid>/stat``, which every Linux kernel has
    (``/proc/<pid>/task/<tid>/children`` needs ``CONFIG_PROC_CHILDREN``, which some lack).
    """
    workers = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or _parent_pid(entry.name) != pid:
            continue
        try:
            if b"spawn_main" in (entry / "cmdline").read_bytes():
                workers.append(int(entry.name))
        except OSError:  # exited meanwhile
            continue
    return workers


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc to find the workers")
def test_a_worker_killed_mid_write_leaves_a_clean_complete_set(tmp_path):
    """kill -9 of both pool workers while a sample is being written: the build re-runs their
    samples, succeeds, and leaves no temporary; check passes. Four samples on two workers: when
    the first temporary appears the others are still queued, so the workers are alive to be
    killed (with two samples the pool could finish and exit before the kill)."""
    ids = (*IDS, "obj-cup__v0__white", "obj-deer__v0__white")
    out = tmp_path / "ds"
    cli = [*CLI[:-1], ",".join(ids)]
    proc = subprocess.Popen(
        [
            sys.executable,
            "-P",
            "-m",
            "spectrinsic",
            *cli,
            "--workers",
            "2",
            "--threads",
            "1",
            "--out",
            str(out),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + WAIT_S
    # a sample's own temporary (``<prefix><id>-*``, made by the worker writing it): the main
    # process briefly makes a write probe with the same prefix, before any worker exists
    while not (
        out.is_dir() and any(p.is_dir() for i in ids for p in out.glob(f"{TMP_PREFIX}{i}-*"))
    ):
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            pytest.fail(f"the build never started writing: {proc.communicate()[1][-2000:]}")
        time.sleep(0.002)
    killed = _workers(proc.pid)
    for pid in killed:
        os.kill(pid, signal.SIGKILL)
    stdout, stderr = proc.communicate(timeout=WAIT_S)
    assert killed, "no worker found to kill"
    assert proc.returncode == 0, stderr
    assert f"built {len(ids)}, skipped 0, failed 0" in stdout
    assert not list(out.glob(".spectrinsic-tmp-*"))
    assert check_dataset(out) == []
