"""Issue 36, cause 12: ``export`` never calls a partial export complete.

A sample the manifest lists but that is missing was dropped with ``complete: true``, and an
export during a ``--rebuild`` of the same dataset mixed config hashes (the dataset's lock was
not consulted). Now both are refused in one line before ``--out`` is created.
"""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest

from spectrinsic.cli import main
from spectrinsic.errors import DatasetError, FolderLockedError
from spectrinsic.gt_export.folders.outfolder import LOCK_NAME

pytest.importorskip("webdataset", reason="the shards extra (webdataset) is in the dev extra")

from spectrinsic.gt_export.dataset.shards import write_shards  # noqa: E402
from tests.conftest import one_line_error

HOLD = """
import fcntl, os, sys, time
fd = os.open(sys.argv[1], os.O_RDWR | os.O_CREAT, 0o644)
fcntl.flock(fd, fcntl.LOCK_EX)
print("held", flush=True)
time.sleep(60)
"""


def test_a_listed_sample_that_is_missing_is_refused_before_out_exists(
    built, tmp_path_factory, capsys
):
    shutil.rmtree(built / "a-one")
    out = tmp_path_factory.mktemp("export") / "shards"
    assert main(["-q", "export", str(built), "--out", str(out)]) == 2
    one_line_error(capsys, "a-one", "missing", "manifest.json")
    assert not out.exists()
    with pytest.raises(DatasetError, match="a-one"):
        write_shards(built, out)


def test_a_dataset_held_by_a_build_is_refused(built, tmp_path_factory, capsys):
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(built / LOCK_NAME)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        out = tmp_path_factory.mktemp("export") / "shards"
        assert main(["-q", "export", str(built), "--out", str(out)]) == 2
        one_line_error(capsys, "in use by another spectrinsic run")
        assert not out.exists()
        with pytest.raises(FolderLockedError):
            write_shards(built, out)
    finally:
        holder.kill()
        holder.wait()
    after = tmp_path_factory.mktemp("export") / "after"
    write_shards(built, after)  # the build over, the export goes ahead
    assert (after / "shards.json").is_file()
