"""``build-time.json``: how long a dataset's build took, run by run, on which machine.

Each run of ``spectrinsic dataset`` that finalises a folder appends one :class:`BuildRun` (its
wall time, the samples it built and their summed time, the share inside Mitsuba, the CPUs it
could use, the UTC time it finished), so a build resumed after an interrupt or extended with
``--only`` reports every run, not only its last part. A run with another config (``--rebuild``)
starts the record afresh: the samples of the old config are gone.

It is the one file of a dataset folder that changes from run to run; ``manifest.json``, whose
content the same build reproduces byte for byte, records no time. A run stopped before its end
(Ctrl-C, a killed process) writes no record, so its samples' time is missing; the card says how
many samples have none.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Mapping
from dataclasses import asdict, dataclass, replace
from datetime import UTC, datetime
from pathlib import Path

from ...errors import SampleMetaError
from ...file_writes import write_text_file
from ..sample import CARD_NAME
from ..sample.json_fields import load_json

__all__ = [
    "BUILD_TIME_NAME",
    "BUILD_TIME_LINE",
    "RUN_TIME_FIELDS",
    "reproducible_bytes",
    "BuildRun",
    "BuildRecord",
    "usable_cpus",
    "utc_now",
    "read_build_record",
    "record_build_run",
]

log = logging.getLogger(__name__)

#: The dataset folder's build-time record (beside ``manifest.json``).
BUILD_TIME_NAME = "build-time.json"
#: Layout of :data:`BUILD_TIME_NAME`.
_FORMAT = 1
#: How the dataset card's one line of build time, machine and date starts (every figure of
#: the card that changes from run to run is on it).
BUILD_TIME_LINE = "Build time:"
#: The fields of a :class:`BuildRun` that a rerun of the same build changes.
RUN_TIME_FIELDS = ("finished", "wall_seconds", "sample_seconds", "mitsuba_seconds", "cpus")


@dataclass(frozen=True)
class BuildRun:
    """One run of a build on a dataset folder.

    Attributes
    ----------
    finished
        When the run wrote its record, UTC, ISO 8601 to the second.
    wall_seconds
        Wall time from the run's start through writing ``manifest.json``, s (planning, every
        sample, the manifest's hashes; the card and gallery written after it are not included).
    samples_built
        Sample folders the run wrote, relit variants (``--relight``) included.
    sample_seconds
        Time of the built samples' tasks (scene, render, ground truth, previews, relit
        variants), summed over samples, s. Workers run in parallel, so it may exceed
        *wall_seconds*.
    mitsuba_seconds
        The part of *sample_seconds* inside Mitsuba's ``render`` calls, s.
    cpus
        CPUs the build process could use (its affinity set).
    """

    finished: str
    wall_seconds: float
    samples_built: int
    sample_seconds: float
    mitsuba_seconds: float
    cpus: int

    @classmethod
    def from_dict(cls, record: Mapping[str, object]) -> BuildRun:
        """A run from its JSON object; ``ValueError`` names the field that is not as written."""
        if set(record) != set(cls.__dataclass_fields__):
            raise ValueError(f"run keys {sorted(record)}")
        finished = record["finished"]
        if not isinstance(finished, str):
            raise ValueError("finished: expected a text")
        return cls(
            finished=finished,
            wall_seconds=_seconds(record, "wall_seconds"),
            samples_built=_count(record, "samples_built"),
            sample_seconds=_seconds(record, "sample_seconds"),
            mitsuba_seconds=_seconds(record, "mitsuba_seconds"),
            cpus=_count(record, "cpus"),
        )

    def finished_after(self, seconds: float) -> BuildRun:
        """This run with *seconds* more wall time, finished now."""
        return replace(self, wall_seconds=self.wall_seconds + seconds, finished=utc_now())


def _seconds(record: Mapping[str, object], key: str) -> float:
    value = record[key]
    if isinstance(value, bool) or not isinstance(value, int | float) or not value >= 0:
        raise ValueError(f"{key}: expected seconds >= 0, got {value!r}")
    return float(value)


def _count(record: Mapping[str, object], key: str) -> int:
    value = record[key]
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"{key}: expected a count >= 0, got {value!r}")
    return value


@dataclass(frozen=True)
class BuildRecord:
    """Every recorded run of one config's build on a folder, oldest first."""

    config_hash: str
    runs: tuple[BuildRun, ...]

    @property
    def wall_seconds(self) -> float:
        """The build's wall time: the sum over its runs, s."""
        return sum(r.wall_seconds for r in self.runs)

    @property
    def sample_seconds(self) -> float:
        """The built samples' time summed over every run, s."""
        return sum(r.sample_seconds for r in self.runs)

    @property
    def mitsuba_seconds(self) -> float:
        """The part of :attr:`sample_seconds` inside Mitsuba, s."""
        return sum(r.mitsuba_seconds for r in self.runs)

    @property
    def samples_built(self) -> int:
        """Sample folders written, summed over the runs (a sample re-rendered counts again)."""
        return sum(r.samples_built for r in self.runs)

    @property
    def outside_mitsuba(self) -> float | None:
        """Share of :attr:`sample_seconds` outside Mitsuba; ``None`` when no sample was timed."""
        total = self.sample_seconds
        return (total - self.mitsuba_seconds) / total if total > 0 else None

    @property
    def resumed(self) -> bool:
        """Whether the build took more than one run."""
        return len(self.runs) > 1


def usable_cpus() -> int:
    """CPUs this process may run on (its affinity set where the OS has one)."""
    affinity = getattr(os, "sched_getaffinity", None)
    return len(affinity(0)) if affinity is not None else os.cpu_count() or 1


def utc_now() -> str:
    """The current UTC time, ISO 8601 to the second (``2026-12-05T13:02:00+00:00``)."""
    return datetime.now(UTC).isoformat(timespec="seconds")


def read_build_record(dataset_dir: str | os.PathLike[str], config_hash: str) -> BuildRecord | None:
    """The runs recorded in *dataset_dir* for *config_hash*; ``None`` when there is no record,
    it belongs to another config, or it is not readable (logged: that build's time is lost)."""
    path = Path(dataset_dir) / BUILD_TIME_NAME
    if not path.is_file():
        return None
    try:
        record = load_json(path)
        if not isinstance(record, dict) or record.get("format") != _FORMAT:
            raise ValueError(f"expected a {BUILD_TIME_NAME} of format {_FORMAT}")
        runs = record.get("runs")
        if not isinstance(runs, list) or not all(isinstance(r, dict) for r in runs):
            raise ValueError("runs: expected a list of objects")
        parsed = tuple(BuildRun.from_dict(r) for r in runs)
    except (SampleMetaError, ValueError) as exc:
        log.warning(
            "%s: not a build-time record (%s); earlier runs' time is not counted", path, exc
        )
        return None
    if record.get("config_hash") != config_hash:
        return None
    return BuildRecord(config_hash=config_hash, runs=parsed)


def record_build_run(
    dataset_dir: str | os.PathLike[str], config_hash: str, run: BuildRun
) -> BuildRecord:
    """Append *run* to the folder's record for *config_hash* (a record of another config is
    replaced) and write it; return the whole record."""
    previous = read_build_record(dataset_dir, config_hash)
    runs = (previous.runs if previous is not None else ()) + (run,)
    record = BuildRecord(config_hash=config_hash, runs=runs)
    data = {
        "format": _FORMAT,
        "config_hash": config_hash,
        "runs": [asdict(r) for r in runs],
    }
    text = json.dumps(data, indent=1, sort_keys=True, allow_nan=False) + "\n"
    write_text_file(Path(dataset_dir) / BUILD_TIME_NAME, text)
    return record


def reproducible_bytes(path: Path) -> bytes:
    """*path*'s bytes less what a rerun of the same build changes: the card's
    :data:`BUILD_TIME_LINE` line, and the :data:`RUN_TIME_FIELDS` of each run in
    :data:`BUILD_TIME_NAME` (each run's sample count is kept). Other files are returned whole.
    What a byte-for-byte comparison of two builds compares (``scripts/byte_identity.py``
    applies the same rule)."""
    if path.name == CARD_NAME:
        lines = path.read_bytes().splitlines(keepends=True)
        return b"".join(x for x in lines if not x.startswith(BUILD_TIME_LINE.encode()))
    if path.name == BUILD_TIME_NAME:
        record = json.loads(path.read_text(encoding="utf-8"))
        for run in record.get("runs", []):
            for key in RUN_TIME_FIELDS:
                run.pop(key, None)
        return json.dumps(record, sort_keys=True).encode()
    return path.read_bytes()
