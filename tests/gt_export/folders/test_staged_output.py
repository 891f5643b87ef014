"""A run writing through staged_output leaves --out as it was when it fails."""

from __future__ import annotations

import pytest

from spectrinsic.gt_export.folders.outfolder import OUTPUT_MARKER
from spectrinsic.gt_export.folders.staged_output import staged_output


def _tree(root):
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*"))


def test_a_failed_run_leaves_no_new_folder(tmp_path):
    out = tmp_path / "out"
    with pytest.raises(RuntimeError), staged_output(out) as stage:
        (stage / "figures").mkdir()
        (stage / "figures" / "a.png").write_bytes(b"x")
        raise RuntimeError("refused at the second sample")
    assert not out.exists()


def test_a_failed_run_leaves_an_earlier_result_as_it_was(tmp_path):
    out = tmp_path / "out"
    with staged_output(out) as stage:
        (stage / "REPORT.md").write_text("first")
    before = _tree(out)
    assert "REPORT.md" in before and OUTPUT_MARKER in before
    with pytest.raises(KeyboardInterrupt), staged_output(out) as stage:
        (stage / "REPORT.md").write_text("second")
        (stage / "estimates").mkdir()
        (stage / "estimates" / "x.exr").write_bytes(b"x")
        raise KeyboardInterrupt
    assert (out / "REPORT.md").read_text() == "first"
    assert [p for p in _tree(out) if not p.startswith(".spectrinsic-lock")] == [
        p for p in before if not p.startswith(".spectrinsic-lock")
    ]


def test_a_finished_run_moves_its_files_in_and_records_them(tmp_path):
    out = tmp_path / "out"
    with staged_output(out) as stage:
        (stage / "figures").mkdir()
        (stage / "figures" / "a.png").write_bytes(b"x")
    assert (out / "figures" / "a.png").read_bytes() == b"x"
    assert "figures/a.png" in (out / OUTPUT_MARKER).read_text()
    assert not [p for p in out.iterdir() if p.name.startswith(".spectrinsic-tmp")]
