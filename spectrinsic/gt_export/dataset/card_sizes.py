"""The dataset card's "Size and build time" section: this set's own figures.

The sizes come from :func:`~spectrinsic.gt_export.dataset.disk_use.disk_use` (the sample
folders as they are when the card is written), the time from the build's record
(:mod:`~spectrinsic.gt_export.dataset.build_time`). Sizes are in decimal units (1 MB = 10⁶
bytes). Every figure that changes from run to run (times, dates, CPUs) is on the one line that
starts with :data:`~.build_time.BUILD_TIME_LINE`, so a reproducibility check can leave exactly
that line out (:func:`~.build_time.reproducible_bytes`, ``scripts/byte_identity.py``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .build_time import BUILD_TIME_LINE, BUILD_TIME_NAME, BuildRecord
from .card_text import percent
from .disk_use import PROJECTED_SAMPLES, ByteStats, DiskUse

__all__ = ["byte_size", "duration", "size_section"]

_UNITS = ("B", "kB", "MB", "GB", "TB", "PB", "EB")


def _three_figures(value: float) -> float:
    """*value* (> 0) rounded to 3 significant figures."""
    return round(value, 2 - int(math.floor(math.log10(value))))


def byte_size(n: float) -> str:
    """*n* bytes in decimal units, 3 significant figures (whole bytes below 1 kB).

    >>> [byte_size(n) for n in (0, 999, 1000, 12_040_000, 476e9, 2.35e12)]
    ['0 B', '999 B', '1.00 kB', '12.0 MB', '476 GB', '2.35 TB']
    """
    if n < 999.5:  # whole bytes; 999.5 B shows as 1.00 kB
        return f"{n:.0f} B"
    last = len(_UNITS) - 1
    power = min(int(math.log10(n) // 3), last)
    value = n / 1000**power
    if _three_figures(value) >= 1000 and power < last:  # 999.96 MB shows as 1.00 GB
        power, value = power + 1, value / 1000
    digits = max(0, 2 - int(math.floor(math.log10(_three_figures(value)))))
    return f"{value:.{digits}f} {_UNITS[power]}"


def duration(seconds: float) -> str:
    """*seconds* for a person: s below 2 min, min below 2 h, else h.

    >>> [duration(s) for s in (0.42, 86.0, 1320.0, 30600.0)]
    ['0.4 s', '86.0 s', '22.0 min', '8.5 h']
    """
    if seconds < 120:
        return f"{seconds:.1f} s"
    if seconds < 7200:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def _folders(n: int) -> str:
    return f"{n} sample folder" + ("" if n == 1 else "s")


def _row(label: str, stats: ByteStats) -> str:
    cells = (stats.mean, stats.smallest, stats.largest, stats.total, stats.projected)
    return f"| {label} | {stats.samples} | " + " | ".join(byte_size(c) for c in cells) + " |"


def _size_table(use: DiskUse) -> str:
    rows = [_row("all, without previews", use.data)]
    kinds = use.by_kind
    if len(kinds) > 1:  # the kinds differ several fold: a mean over the mix describes none
        rows += [_row(f"with {kind}" if kind != "plain" else kind, s) for kind, s in kinds.items()]
    rows.append(_row("previews only (`previews/`, PNG)", use.previews))
    head = (
        "| samples | count | mean | smallest | largest | whole set | "
        f"per {PROJECTED_SAMPLES:,} (projection) |\n|---|---|---|---|---|---|---|"
    )
    return head + "\n" + "\n".join(rows)


def _build_time_line(record: BuildRecord | None, n_samples: int, variants: Sequence[str]) -> str:
    """The card's one line of time, machine and date (see :data:`BUILD_TIME_LINE`)."""
    if record is None or not record.runs:
        return (
            f"{BUILD_TIME_LINE} not recorded (no `{BUILD_TIME_NAME}` for this configuration: "
            "the set was not built by `spectrinsic dataset`, or before build times were recorded)."
        )
    runs = record.runs
    when = (
        f"over {len(runs)} runs (a resumed build: their wall times summed; the last run "
        f"{duration(runs[-1].wall_seconds)}), the first finished {runs[0].finished}, the last "
        f"{runs[-1].finished}"
        if record.resumed
        else f"in one run, finished {runs[0].finished}"
    )
    built = record.samples_built
    cpus = ", ".join(str(c) for c in sorted({r.cpus for r in runs}))
    text = f"{BUILD_TIME_LINE} **{duration(record.wall_seconds)}** of wall time {when}"
    if built:
        share = record.outside_mitsuba
        outside = (
            f", {percent(share)} of it outside Mitsuba (scene, ground truth, denoising, previews)"
            if share is not None
            else ""
        )
        text += (
            f"; the {_folders(built)} built took {duration(record.sample_seconds)} summed "
            f"over samples ({duration(record.sample_seconds / built)} per folder){outside}"
        )
    machine = f"{cpus} CPU" + ("" if cpus == "1" else "s")
    text += (
        f"; on {machine}, Mitsuba variant(s) {', '.join(variants)} (`{BUILD_TIME_NAME}`; a "
        "run's wall time runs from its start through writing `manifest.json`, the samples' "
        "time is their tasks' summed over parallel workers)."
    )
    missing = n_samples - built
    if missing > 0:
        verb = "has" if missing == 1 else "have"
        text += (
            f" At least {missing} of the {n_samples} samples {verb} no recorded time (built by "
            "a run stopped before its end, or before build times were recorded)."
        )
    return text


def size_section(use: DiskUse, record: BuildRecord | None, variants: Sequence[str]) -> str:
    """The card's "Size and build time" section (Markdown, heading included)."""
    n = len(use.samples)
    verb = "holds" if n == 1 else "hold"
    return (
        "## Size and build time\n\n"
        f"Measured from this folder when this card was written: its {_folders(n)} {verb} "
        f"**{byte_size(use.total)}**, previews included (file sizes in decimal units, "
        "1 MB = 10⁶ bytes; `manifest.json`, this card and the gallery are not counted). Per "
        "sample:\n\n"
        f"{_size_table(use)}\n\n"
        f"The last column is a projection, {PROJECTED_SAMPLES:,} × the mean, not a measurement: "
        "another resolution, more lights or glossy materials give other sizes.\n\n"
        f"{_build_time_line(record, n, variants)}\n"
    )
