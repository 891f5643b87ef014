"""The real pipeline end to end on two tiny samples: build, resume, determinism, config changes,
crashes and interrupts.

Samples are 12 x 12 pixels at 2 spp (a second or two each): these tests check the bookkeeping,
not image quality. One sample is an object under one light, the other a room under two lights
(per-light renders, illuminant map).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import check_dataset, is_complete
from spectrinsic.gt_export.dataset.gallery import GALLERY_DIRS
from spectrinsic.pipeline.dataset import build_dataset
from spectrinsic.pipeline.executors import ProcessExecutor
from spectrinsic.pipeline.presets import DatasetConfig, get_preset
from spectrinsic.rng import seed_from_key

TINY = DatasetConfig.from_settings(
    "tiny-test",
    width=12,
    height=12,
    spp=2,
    max_depth=3,
    modes=("spectral", "rgb3"),
    per_light=True,
    seed=5,
)
IDS = ("obj-apple__v0__white", "room-living__v0__two-colour-a")
ONLY = ",".join(IDS)
#: A run that skips every sample only reads two meta.json files and rewrites manifest, card and
#: gallery: well under a second here; generous for a loaded 2-core machine.
RESUME_MAX_S = 5.0
#: How long the subprocess tests wait for a build to reach the state they interrupt.
WAIT_S = 120.0
#: CLI arguments that build the two tiny samples (the preview preset, shrunk further).
CLI_TINY = ["--preset", "preview", "--resolution", "12x12", "--spp", "2", "--only", ONLY]
CLI_HASH = get_preset("preview").with_options(width=12, height=12, spp=2).config_hash()


def _hashes(root: Path) -> dict[str, str]:
    """SHA-256 of every file in the sample folders and of manifest.json."""
    out = {}
    for sample in IDS:
        for p in sorted((root / sample).rglob("*")):
            if p.is_file():
                out[p.relative_to(root).as_posix()] = hashlib.sha256(p.read_bytes()).hexdigest()
    out["manifest.json"] = hashlib.sha256((root / "manifest.json").read_bytes()).hexdigest()
    return out


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory):
    """The two tiny samples, built once serially in this process."""
    out = tmp_path_factory.mktemp("tiny") / "dataset"
    report = build_dataset(out, TINY, only=ONLY)
    return out, report


def test_two_real_samples_end_to_end(built):
    out, report = built
    assert report.ok, report.failed
    assert [o.sample_id for o in report.built] == sorted(IDS)
    assert report.skipped == ()
    assert check_dataset(out) == []
    for name in ("manifest.json", "DATASET.md", "index.html"):
        assert (out / name).is_file(), name
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["config_hash"] == TINY.config_hash()
    assert sorted(manifest["samples"]) == sorted(IDS)
    for sample_id in IDS:
        meta = json.loads((out / sample_id / "meta.json").read_text())
        assert meta["config_hash"] == TINY.config_hash()
        assert meta["seed"] == seed_from_key(TINY.seed, sample_id)  # recorded per-sample seed
    # the worker reports where its time went
    for o in report.built:
        assert 0 < o.mitsuba_seconds <= o.render_seconds <= o.seconds
        assert o.peak_rss_mb > 0


def test_second_run_skips_everything_quickly(built):
    out, _ = built
    before = {p: p.stat().st_mtime_ns for p in out.glob("*/*.exr")}
    start = time.perf_counter()
    report = build_dataset(out, TINY, only=ONLY)
    elapsed = time.perf_counter() - start
    assert report.built == () and report.failed == ()
    assert sorted(o.sample_id for o in report.skipped) == sorted(IDS)
    assert elapsed < RESUME_MAX_S
    assert {p: p.stat().st_mtime_ns for p in out.glob("*/*.exr")} == before  # nothing rewritten


def test_same_config_and_seed_give_identical_files(built, tmp_path):
    """Rebuilt in two spawned workers with one render thread each (the first build ran in this
    process with Dr.Jit's default thread count): every file is byte-identical."""
    out, _ = built
    again = tmp_path / "again"
    report = build_dataset(
        again, TINY, only=ONLY, executor=ProcessExecutor(workers=2), render_threads=1
    )
    assert report.ok, report.failed
    first, second = _hashes(out), _hashes(again)
    assert any(k.endswith("image.exr") for k in first)
    assert first == second


def test_config_change_rerenders(built, tmp_path):
    out, _ = built
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    changed = TINY.with_options(spp=TINY.render.spp * 2)
    assert changed.config_hash() != TINY.config_hash()
    with pytest.raises(DatasetError, match="--rebuild"):  # one config per dataset folder
        build_dataset(copy, changed, only=ONLY)
    assert _hashes(copy) == _hashes(out)  # refused before touching anything
    report = build_dataset(copy, changed, only=ONLY, rebuild=True)
    assert sorted(o.sample_id for o in report.built) == sorted(IDS)
    assert report.skipped == ()
    for sample_id in IDS:
        assert is_complete(copy / sample_id, changed.config_hash())
        assert not is_complete(copy / sample_id, TINY.config_hash())
        old = (out / sample_id / "image.exr").read_bytes()
        assert (copy / sample_id / "image.exr").read_bytes() != old  # new pixels


def test_crash_while_writing_leaves_no_complete_looking_folder(tmp_path, monkeypatch):
    """A sample whose export dies half-way is reported failed and leaves no folder under its
    name; the other sample still builds; a re-run completes the set."""
    import spectrinsic.gt_export.sample.writer as writer

    real_write_exr = writer.write_exr
    calls = []

    def dying_write_exr(path, *args, **kwargs):
        calls.append(path)
        if "room-living" in str(path) and len([c for c in calls if "room" in str(c)]) == 2:
            raise OSError("simulated crash while writing the second EXR")
        return real_write_exr(path, *args, **kwargs)

    monkeypatch.setattr(writer, "write_exr", dying_write_exr)
    out = tmp_path / "ds"
    report = build_dataset(out, TINY, only=ONLY, finalize=False)
    assert [f.sample_id for f in report.failed] == [IDS[1]]
    assert "simulated crash" in report.failed[0].error
    assert [o.sample_id for o in report.built] == [IDS[0]]
    assert not (out / IDS[1]).exists()
    assert not is_complete(out / IDS[1], TINY.config_hash())

    monkeypatch.setattr(writer, "write_exr", real_write_exr)
    report = build_dataset(out, TINY, only=ONLY)
    assert [o.sample_id for o in report.built] == [IDS[1]]
    assert [o.sample_id for o in report.skipped] == [IDS[0]]
    assert check_dataset(out) == []


def _cli(out: Path, *extra: str, new_session: bool = False) -> subprocess.Popen[str]:
    """The dataset verb in a child process (one worker unless *extra* says otherwise); in a
    process group of its own with *new_session*, as a terminal runs it."""
    return subprocess.Popen(
        [
            sys.executable,
            "-P",
            "-m",
            "spectrinsic",
            "-q",
            "dataset",
            "--out",
            str(out),
            "--workers",
            "1",
            *CLI_TINY,
            *extra,
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=new_session,
        # Ctrl-C as a terminal delivers it: the child takes SIGINT even if this test process
        # was started with it ignored (a background job of a script), which children inherit
        preexec_fn=_default_sigint,
    )


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _wait_for(predicate, proc: subprocess.Popen[str], what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not predicate():
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            out, err = proc.communicate()
            pytest.fail(f"the build never reached {what} (rc {proc.returncode}): {err[-2000:]}")
        time.sleep(0.002)


@pytest.mark.slow
def test_hard_kill_mid_write_then_rerun_completes(tmp_path):
    """SIGKILL (no clean-up at all) while a sample is being written: the half-written sample
    sits in a hidden temporary folder, never under its own name; a re-run removes it and
    completes the set."""
    out = tmp_path / "ds"
    proc = _cli(out)

    def writing() -> bool:
        # a sample's own temporary: the main process's brief write probe has the same prefix
        return out.is_dir() and any(
            p.is_dir() for i in IDS for p in out.glob(f".spectrinsic-tmp-{i}-*")
        )

    _wait_for(writing, proc, "the middle of writing a sample")
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert any(p.name.startswith(".spectrinsic-tmp-") for p in out.iterdir())
    for sample_id in IDS:
        # a folder under a sample's own name is always whole
        folder = out / sample_id
        assert not folder.exists() or is_complete(folder, CLI_HASH), sample_id
    assert not all((out / s).exists() for s in IDS), "the kill came after the last sample"

    rerun = _cli(out)
    stdout, stderr = rerun.communicate(timeout=WAIT_S)
    assert rerun.returncode == 0, stderr
    assert not list(out.glob(".spectrinsic-tmp-*"))
    assert check_dataset(out) == []
    folders = sorted(p.name for p in out.iterdir() if p.is_dir() and p.name not in GALLERY_DIRS)
    assert folders == sorted(IDS)


@pytest.mark.slow
@pytest.mark.parametrize("workers", ["1", "2"])
def test_ctrl_c_keeps_completed_samples(tmp_path, workers):
    """Ctrl-C as a terminal sends it (SIGINT to the whole process group), once a first sample
    is whole, i.e. while the next ones render: Mitsuba's own SIGINT handler must not swallow it
    (issue 17: rc 0 and the whole build went on with one worker). rc 130, completed samples
    kept whole, the interrupted one a temporary that the re-run removes."""
    # Four samples: the other three cannot all finish in the moment the signal takes to arrive,
    # so the interrupt always lands mid-build.
    ids = (
        "obj-apple__v0__white",
        "obj-box__v0__white",
        "obj-cup__v0__white",
        "obj-deer__v0__white",
    )
    out = tmp_path / "ds"
    proc = _cli(out, "--only", ",".join(ids), "--workers", workers, new_session=True)

    def one_done() -> bool:
        return any((out / s / "meta.json").is_file() for s in ids)

    _wait_for(one_done, proc, "one complete sample")
    os.killpg(proc.pid, signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=WAIT_S)
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr
    assert "winding down" not in stderr  # Mitsuba's handler never saw the signal
    done = [s for s in ids if (out / s).exists()]
    assert 1 <= len(done) < len(ids)
    assert all(is_complete(out / s, CLI_HASH) for s in done)  # kept, whole

    rerun = _cli(out, "--only", ",".join(ids))
    stdout, stderr = rerun.communicate(timeout=WAIT_S)
    assert rerun.returncode == 0, stderr
    assert f"built {len(ids) - len(done)}, skipped {len(done)}, failed 0" in stdout
    assert not list(out.glob(".spectrinsic-tmp-*"))
    assert check_dataset(out) == []


def test_cli_reports_failures_and_exits_nonzero(tmp_path, monkeypatch, capsys):
    import spectrinsic.pipeline.dataset as pipeline_dataset
    from spectrinsic.cli import main

    real = pipeline_dataset.render_batches

    def failing_for_rooms(scene, settings, **kwargs):
        if scene.name.startswith("room-"):
            raise RuntimeError("simulated render failure")
        return real(scene, settings, **kwargs)

    monkeypatch.setattr(pipeline_dataset, "render_batches", failing_for_rooms)
    rc = main(["-q", "dataset", "--out", str(tmp_path / "ds"), "--workers", "1", *CLI_TINY])
    captured = capsys.readouterr()
    assert rc == 1
    assert "built 1, skipped 0, failed 1" in captured.out
    assert f"FAILED {IDS[1]}: RuntimeError: simulated render failure" in captured.out
    assert IDS[1] in captured.err
    assert (tmp_path / "ds" / IDS[0] / "meta.json").is_file()  # the other sample was built


@pytest.mark.slow
def test_dask_cluster_builds_the_same_files(built, tmp_path):
    """The real pipeline through a Dask LocalCluster gives the same bytes as the serial build."""
    distributed = pytest.importorskip("distributed", reason="dask.distributed not installed")
    from spectrinsic.pipeline.executors import DaskExecutor

    out, _ = built
    again = tmp_path / "dask"
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        report = build_dataset(
            again, TINY, only=ONLY, executor=DaskExecutor(cluster.scheduler_address)
        )
    assert report.ok, report.failed
    assert _hashes(out) == _hashes(again)
