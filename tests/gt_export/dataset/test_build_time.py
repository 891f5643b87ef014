"""The card's build time is the whole build's (issue 45): a resumed build's time is the sum
over its runs, a run of another config starts afresh, and samples whose run left no record are
counted, not hidden.

The builds here run the real pipeline (plan, skip, finalise: manifest, record, card, gallery)
with a task that writes a synthetic sample and reports fixed times instead of rendering.
"""

from __future__ import annotations

import json
import logging
import time
from pathlib import Path

import pytest

from spectrinsic.gt_export.dataset.build_time import (
    BUILD_TIME_LINE,
    BUILD_TIME_NAME,
    BuildRun,
    read_build_record,
    record_build_run,
)
from spectrinsic.gt_export.dataset.card_sizes import duration
from spectrinsic.gt_export.dataset.card_text import percent
from spectrinsic.pipeline.dataset import build_dataset
from spectrinsic.pipeline.presets import DatasetConfig
from spectrinsic.pipeline.tasks import SampleOutcome, SampleTask

CONFIG = DatasetConfig.from_settings(
    "tiny-test", width=12, height=12, spp=2, max_depth=3, modes=("spectral", "rgb3"), seed=5
)
IDS = ("obj-apple__v0__white", "room-living__v0__two-colour-a")
#: The times the fake task reports for each sample, s.
SECONDS, MITSUBA_SECONDS = 1.5, 0.5


def _fake_task(synth):
    """A task that writes a synthetic sample (no render) and reports fixed times."""
    from spectrinsic.gt_export import export_sample

    def task(t: SampleTask) -> SampleOutcome:
        scene = synth.make_scene(("planck:2800K",))
        cfg = t.config.to_dict()
        path = export_sample(
            t.out_dir,
            scene,
            synth.make_result(scene),
            sample_id=t.sample_id,
            config=cfg,
            seed=t.seed,
        )
        time.sleep(0.05)  # every run takes measurable wall time
        return SampleOutcome(t.sample_id, "built", str(path), SECONDS, 1.0, MITSUBA_SECONDS)

    return task


def _time_line(root: Path) -> str:
    card = (root / "DATASET.md").read_text(encoding="utf-8")
    lines = [line for line in card.splitlines() if line.startswith(BUILD_TIME_LINE)]
    assert len(lines) == 1  # every run-dependent figure on one line (scripts/byte_identity.py)
    return lines[0]


def test_a_resumed_builds_time_is_the_sum_of_its_runs(tmp_path, synth):
    out = tmp_path / "set"
    task = _fake_task(synth)
    kw = {"task_fn": task, "disk_check": False}
    first = build_dataset(out, CONFIG, only=IDS[0], **kw)
    one = read_build_record(out, CONFIG.config_hash())
    assert one is not None and len(one.runs) == 1 and not one.resumed
    assert "in one run" in _time_line(out)
    second = build_dataset(out, CONFIG, only=",".join(IDS), **kw)  # resumed: builds the other
    assert [o.sample_id for o in second.built] == [IDS[1]] and len(second.skipped) == 1

    record = read_build_record(out, CONFIG.config_hash())
    assert record is not None and record.resumed
    runs = record.runs
    assert [r.samples_built for r in runs] == [1, 1]
    assert record.sample_seconds == 2 * SECONDS  # both runs' samples, not only the last one's
    assert record.outside_mitsuba == pytest.approx(1 - MITSUBA_SECONDS / SECONDS)
    assert record.wall_seconds == pytest.approx(runs[0].wall_seconds + runs[1].wall_seconds)
    assert runs[0].wall_seconds == one.runs[0].wall_seconds  # the first run's kept as recorded
    for run, report in zip(runs, (first, second), strict=True):
        assert 0.05 < run.wall_seconds <= report.seconds  # through the manifest, not the gallery
    line = _time_line(out)
    assert f"**{duration(record.wall_seconds)}** of wall time over 2 runs" in line
    assert f"the 2 sample folders built took {duration(2 * SECONDS)} summed" in line
    assert f"{percent(1 - MITSUBA_SECONDS / SECONDS)} of it outside Mitsuba" in line
    assert "no recorded time" not in line


def test_samples_without_a_recorded_time_are_counted(tmp_path, synth):
    """A run stopped before its end left samples but no record: the card says so."""
    out = tmp_path / "set"
    build_dataset(out, CONFIG, only=",".join(IDS), task_fn=_fake_task(synth), disk_check=False)
    (out / BUILD_TIME_NAME).unlink()
    record_build_run(
        out, CONFIG.config_hash(), BuildRun("2026-12-05T13:00:00+00:00", 2, 1, 3, 1, 2)
    )
    from spectrinsic.gt_export.dataset.card import write_dataset_card

    write_dataset_card(out, CONFIG.to_dict())
    line = _time_line(out)
    assert "At least 1 of the 2 samples has no recorded time" in line
    assert "finished 2026-12-05T13:00:00+00:00" in line and "on 2 CPUs" in line


def test_a_record_of_another_config_is_replaced(tmp_path):
    run = BuildRun("2026-12-05T13:00:00+00:00", 10.0, 2, 8.0, 4.0, 2)
    record_build_run(tmp_path, "old", run)
    assert read_build_record(tmp_path, "new") is None
    record = record_build_run(tmp_path, "new", run)
    assert len(record.runs) == 1
    assert read_build_record(tmp_path, "old") is None  # --rebuild: the old runs are gone
    stored = json.loads((tmp_path / BUILD_TIME_NAME).read_text())
    assert stored["config_hash"] == "new" and len(stored["runs"]) == 1


@pytest.mark.parametrize(
    "text",
    [
        "not json",
        '{"format": 1, "config_hash": "h", "runs": [{"finished": "x"}]}',
        '{"format": 1, "config_hash": "h", "runs": [{"finished": "x", "wall_seconds": -1, '
        '"samples_built": 1, "sample_seconds": 1, "mitsuba_seconds": 1, "cpus": 1}]}',
    ],
)
def test_an_unreadable_record_is_reported_and_not_counted(tmp_path, caplog, text):
    (tmp_path / BUILD_TIME_NAME).write_text(text)
    with caplog.at_level(logging.WARNING):
        assert read_build_record(tmp_path, "h") is None
    assert "not a build-time record" in caplog.text
