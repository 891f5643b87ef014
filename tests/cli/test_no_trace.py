"""Issue 36, cause 11: a refusal, a full disk or a kill leaves no trace.

* A full disk is a real one: each command runs with ``--out`` on a small ``tmpfs`` mounted in
  a private mount namespace (``unshare --user --map-root-user --mount``, no root needed where
  user namespaces are allowed), so every writer fails with the kernel's ``ENOSPC``, C
  libraries (OpenEXR) included. Each run must end with rc 2 and one line naming a file under
  ``--out``, leave nothing in a folder it created (no zero-byte temporary, no partial file),
  and, once the disk has room again (the ``tmpfs`` is remounted larger), the same command must
  finish (rc 0) with nothing of spectrinsic's temporaries left.
* A kill is a real one: the command runs in a child process that gets SIGTERM or SIGKILL while
  its temporaries are on disk; SIGTERM stops it like Ctrl-C (rc 143, its folder as before) and
  after SIGKILL the same command resumes into its folder and sweeps what the killed run left.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
import traceback
from collections.abc import Callable
from pathlib import Path

import pytest

from spectrinsic.cli import main
from tests.conftest import QUAD_YAML

#: The tmpfs sizes tried per command, as fractions of what its whole output takes: the first
#: file fails, or one of the last (a dataset's own files after its samples, meta.json).
FRACTIONS = (0.0, 0.85)
#: What a run whose disk filled must leave in a folder it created: nothing.
_TMP = ".spectrinsic-tmp-"


def _unshare_works() -> bool:
    if shutil.which("unshare") is None or shutil.which("mount") is None:
        return False
    probe = subprocess.run(
        ["unshare", "-rm", "sh", "-c", "mount -t tmpfs -o size=8k tmpfs /mnt || exit 1"],
        capture_output=True,
        check=False,
    )
    return probe.returncode == 0


def _cases(inputs: dict[str, str]) -> dict[str, list[str]]:
    """Each writing verb's command line, writing into ``out`` (relative to the small disk)."""
    scene, ds, sample = inputs["scene"], inputs["dataset"], inputs["sample"]
    return {
        "render": ["render", scene, "--out", "out", "-q"],
        "render --ground-truth": ["render", scene, "--ground-truth", "--out", "out", "-q"]
        + ["--ignore-disk-space"],  # past the estimate (tested below): to the disk itself
        "dataset": ["dataset", "--scenes", scene, "--out", "out", "-q", "--ignore-disk-space"],
        "relight": ["relight", sample, "--light", "0=planck:3000K", "--out", "out", "-q"],
        "export": ["export", ds, "--out", "out", "-q"],
        "evaluate": ["evaluate", "--dataset", ds, "--methods", "image-as-shading"]
        + ["--no-figures", "--out", "out", "-q"],
        "study": ["study", "photometric", "--out", "out", "-q"],
    }


def _listing(root: Path) -> dict[str, int]:
    return {
        p.relative_to(root).as_posix(): p.stat().st_size
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def _run_captured(argv: list[str], err_file: Path) -> tuple[int, str]:
    """``main(argv)`` with file descriptor 2 (C libraries' stderr too) sent to *err_file*."""
    saved = os.dup(2)
    with err_file.open("w") as fh:
        os.dup2(fh.fileno(), 2)
        try:
            rc = main(argv)
        except Exception:  # what would reach the user as a traceback: recorded as one
            traceback.print_exc()
            rc = 1
        finally:
            sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)
    return rc, err_file.read_text()


def _driver(work: Path) -> None:
    """Inside the private mount namespace: every case on a small tmpfs, then with room."""
    scene = work / "scene.yaml"
    scene.write_text(QUAD_YAML)
    ds = work / "ds"
    assert (
        main(["dataset", "--scenes", str(scene), "--out", str(ds), "--store-transport", "-q"]) == 0
    )
    sample = next(p for p in ds.iterdir() if (p / "meta.json").is_file())
    inputs = {"scene": str(scene), "dataset": str(ds), "sample": str(sample)}
    results = []
    for name, argv in _cases(inputs).items():
        needed = _mounted(work / f"room-{name}", "16m", argv, work)["used"]
        for fraction in FRACTIONS:
            size = f"{max(8, int(needed * fraction) // 4096 * 4)}k"
            results.append(
                {"case": name, "size": size}
                | _mounted(work / f"disk-{len(results)}", size, argv, work)
            )
    print(json.dumps(results))


def _mounted(disk: Path, size: str, argv: list[str], work: Path) -> dict:
    """Run *argv* in *disk*, a tmpfs of *size*; then with room again (the same command)."""
    disk.mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(disk)], check=True)
    os.chdir(disk)
    try:
        rc, err = _run_captured(argv, work / "err.txt")
        left, used = _listing(disk), shutil.disk_usage(disk).used
        subprocess.run(["mount", "-o", "remount,size=16m", str(disk)], check=True)
        again, _ = _run_captured(argv, work / "err.txt")
        return {"rc": rc, "err": err, "left": left, "used": used} | {
            "again": again,
            "after": _listing(disk),
        }
    finally:
        os.chdir(work)


@pytest.fixture(scope="module")
def full_disk_runs(tmp_path_factory) -> list[dict]:
    if not _unshare_works():
        pytest.skip("needs user and mount namespaces (unshare -rm) to mount a small tmpfs")
    work = tmp_path_factory.mktemp("full-disk")
    proc = subprocess.run(
        ["unshare", "-rm", sys.executable, __file__, str(work)],
        capture_output=True,
        text=True,
        check=False,
        cwd=Path(__file__).parents[2],
        env={**os.environ, "PYTHONPATH": str(Path(__file__).parents[2])},
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.mark.slow
@pytest.mark.parametrize("case", list(_cases({"scene": "", "dataset": "", "sample": ""})))
def test_a_full_disk_is_one_line_naming_the_file_and_leaves_no_trace(full_disk_runs, case):
    runs = [r for r in full_disk_runs if r["case"] == case]
    assert len(runs) == len(FRACTIONS)
    assert any(r["rc"] != 0 for r in runs), f"{case}: no size filled the disk"
    for r in runs:
        lines = [line for line in r["err"].splitlines() if not line.startswith("WARNING ")]
        if r["rc"] == 0:  # the command fitted: nothing to check but its success
            continue
        assert r["rc"] == 2, r
        assert len(lines) == 1, r["err"]
        assert lines[0].startswith("spectrinsic: error: cannot write 'out/"), lines[0]
        assert "No space left on device" in lines[0], lines[0]
        assert "Traceback" not in r["err"] and "Exception ignored" not in r["err"], r["err"]
        if any(k.endswith("/meta.json") for k in r["left"]):  # a dataset (render --ground-truth)
            # samples were complete when the dataset's own files filled the disk: kept, whole
            assert not any(_TMP in k for k in r["left"]), r["left"]
            assert all(size > 0 for size in r["left"].values()), r["left"]
        else:  # a folder the run created is removed again: nothing at all is left
            assert r["left"] == {}, r["left"]
        # with room again, the same command finishes and leaves no temporary behind
        assert r["again"] == 0, r
        assert r["after"] and not any(_TMP in k for k in r["after"]), r["after"]


# -- kills: SIGTERM is Ctrl-C; after SIGKILL the same command resumes and sweeps -------------


@pytest.fixture(scope="module")
def transport_dataset(tmp_path_factory) -> Path:
    work = tmp_path_factory.mktemp("kills")
    scene = work / "scene.yaml"
    scene.write_text(QUAD_YAML)
    ds = work / "ds"
    assert (
        main(["dataset", "--scenes", str(scene), "--out", str(ds), "--store-transport", "-q"]) == 0
    )
    return ds


def _signal_when(argv: list[str], there: Callable[[], bool], sig: int) -> tuple[int, str]:
    """Run ``spectrinsic *argv*`` in a child; send *sig* as soon as *there()*; (rc, stderr)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "spectrinsic", *argv],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 300
        while not there():
            assert proc.poll() is None, "the command ended before it could be stopped"
            assert time.monotonic() < deadline
            time.sleep(0.002)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=300)
    finally:
        proc.kill()
    return proc.returncode, err


def _evaluate(ds: Path, out: Path) -> list[str]:
    return ["evaluate", "--dataset", str(ds), "--methods", "image-as-shading", "--out", str(out)]


def _stage(out: Path) -> Callable[[], bool]:
    return lambda: any(out.glob(".spectrinsic-tmp-stage-*/*"))


def _ours(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob(f"{_TMP}*"))


def test_sigterm_stops_evaluate_like_ctrl_c(transport_dataset, tmp_path):
    out = tmp_path / "ev"
    rc, err = _signal_when(_evaluate(transport_dataset, out), _stage(out), signal.SIGTERM)
    assert rc == 128 + signal.SIGTERM, err
    assert "interrupted" in err and "Traceback" not in err, err
    assert not out.exists()  # the folder it made, with its staged files, is gone


def test_evaluate_killed_resumes_into_its_folder_and_sweeps_the_killed_runs_files(
    transport_dataset, tmp_path
):
    out = tmp_path / "ev"
    rc, _ = _signal_when(_evaluate(transport_dataset, out), _stage(out), signal.SIGKILL)
    assert rc == -signal.SIGKILL and _ours(out)  # the killed run's staging folder is there
    assert main([*_evaluate(transport_dataset, out), "-q"]) == 0
    assert _ours(out) == [] and (out / "REPORT.md").is_file()


def test_relight_killed_leaves_a_temporary_the_next_run_sweeps(transport_dataset, tmp_path):
    sample = next(p for p in transport_dataset.iterdir() if (p / "meta.json").is_file())
    argv = ["relight", str(sample), "--light", "0=planck:3000K", "--out", str(tmp_path / "rl")]
    writing = lambda: any(tmp_path.glob(".spectrinsic-tmp-rl-*/*"))  # noqa: E731
    rc, _ = _signal_when(argv, writing, signal.SIGKILL)
    assert rc == -signal.SIGKILL and _ours(tmp_path)
    assert main([*argv, "-q"]) == 0
    assert _ours(tmp_path) == [] and (tmp_path / "rl" / "meta.json").is_file()


# -- refusals: what a refused run created is removed ------------------------------------------


def test_a_refused_evaluate_leaves_no_folder_not_even_the_parents_it_made(
    transport_dataset, tmp_path, capsys
):
    sample = next(p for p in transport_dataset.iterdir() if (p / "meta.json").is_file())
    bad = tmp_path / "pred" / sample.name
    bad.mkdir(parents=True)
    (bad / "reflectance.png").write_text("not a PNG")  # refused while scoring, inside --out
    out = tmp_path / "new" / "deeper" / "ev"
    argv = ["evaluate", "--dataset", str(transport_dataset), "--predictions", str(bad.parent)]
    assert main([*argv, "--out", str(out), "-q"]) == 2
    assert "reflectance.png" in capsys.readouterr().err
    assert not (tmp_path / "new").exists()


def test_a_refused_export_leaves_no_index_naming_missing_shards(
    transport_dataset, tmp_path, capsys
):
    ds = tmp_path / "ds"
    shutil.copytree(transport_dataset, ds)
    image = next(ds.glob("*/image.exr"))
    data = bytearray(image.read_bytes())
    data[-200:-100] = bytes(100)  # damaged: refused by its SHA-256 while the shard is written
    image.write_bytes(bytes(data))
    out = tmp_path / "shards"
    assert main(["export", str(ds), "--out", str(out), "-q"]) == 2
    assert "image.exr" in capsys.readouterr().err
    assert not out.exists()


# -- cause 8: a damaged EXR is one line, whatever OpenEXR's C library prints -----------------


def test_a_truncated_exr_is_one_line_on_stderr_and_nothing_on_stdout(transport_dataset, tmp_path):
    import numpy as np

    from spectrinsic.gt_export.formats.exr import write_exr

    sample = next(p for p in transport_dataset.iterdir() if (p / "meta.json").is_file())
    pred = tmp_path / "pred" / sample.name
    pred.mkdir(parents=True)
    noise = np.random.default_rng(0).random((16, 16, 3), np.float32)  # incompressible pixels
    whole = write_exr(tmp_path / "whole.exr", {"": noise})
    for name in ("reflectance.exr", "shading.exr"):  # pixel data cut off halfway
        (pred / name).write_bytes(whole.read_bytes()[: whole.stat().st_size // 2])
    argv = ["evaluate", "--dataset", str(transport_dataset), "--predictions", str(pred.parent)]
    proc = subprocess.run(
        [sys.executable, "-m", "spectrinsic", *argv, "--out", str(tmp_path / "ev"), "-q"],
        capture_output=True,
        text=True,
        check=False,
    )
    err = [line for line in proc.stderr.splitlines() if not line.startswith("WARNING ")]
    assert proc.returncode == 2 and proc.stdout == "", (proc.stdout, proc.stderr)
    assert len(err) == 1 and "reflectance.exr" in err[0] and "cannot be" in err[0], err


if __name__ == "__main__":
    _driver(Path(sys.argv[1]))
