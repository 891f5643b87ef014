"""What an evaluation scored: the dataset, its preset and config hash, the samples and their
lighting, and a warning when the renderings are preview-grade noisy.

``spectrinsic evaluate`` adds :func:`scored_section` to ``REPORT.md`` (under its first
paragraph, :func:`add_scored_section`) and writes the same record as ``scored.json``, so a
report says which data its numbers come from. The lighting groups are measured from each
sample's lights where the sample is not one of the library's conditions
(:func:`spectrinsic.decompose.evaluation.sample_fields.sample_condition`).
"""

from __future__ import annotations

import json
from collections import Counter
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...file_writes import write_text_file
from ...gt_export.dataset.check import NOISE_THRESHOLD
from ...gt_export.sample import MANIFEST_NAME
from ...scenes.lighting import GROUPS
from .sample_fields import sample_condition
from .scores import condition_group

__all__ = ["ScoredSet", "add_scored_section", "describe_scored", "scored_section"]

#: Presets whose renderings are for looking, not for scoring.
PREVIEW_PRESETS = frozenset({"preview"})


@dataclass(frozen=True)
class ScoredSet:
    """The data behind an evaluation's numbers.

    ``noise_median`` is the median over the scored samples of each image's median relative
    standard error (``meta.json["noise"]["image"]``, a fraction; ``None`` when not measured).
    """

    dataset: str
    preset: str | None
    config_hash: str | None
    n_listed: int | None
    n_scored: int
    groups: dict[str, int]
    lights: dict[str, int]
    noise_median: float | None

    @property
    def preview_grade(self) -> bool:
        """Built with a preview preset, or noisier than ``check``'s threshold."""
        noisy = self.noise_median is not None and self.noise_median > NOISE_THRESHOLD
        return noisy or self.preset in PREVIEW_PRESETS


def _json(path: Path) -> dict[str, Any]:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise DatasetError(f"cannot read {str(path)!r}: {exc}") from None
    return data if isinstance(data, dict) else {}


def describe_scored(dataset: Path, folders: Sequence[Path]) -> ScoredSet:
    """The :class:`ScoredSet` of the sample *folders* of *dataset* (a dataset folder, or a
    sample folder itself); reads ``manifest.json`` when there is one and each ``meta.json``."""
    manifest_path = dataset / MANIFEST_NAME
    manifest = _json(manifest_path) if manifest_path.is_file() else {}
    config = manifest.get("config") if isinstance(manifest.get("config"), dict) else {}
    groups: Counter[str] = Counter()
    lights: Counter[str] = Counter()
    noise = []
    hashes = set()
    for folder in folders:
        meta = _json(folder / "meta.json")
        hashes.add(meta.get("config_hash") if isinstance(meta.get("config_hash"), str) else "")
        # the evaluation's own grouping; refuses a sample it could not group, before any work
        sample = {"meta": {"sample_id": folder.name, **meta}}
        groups[condition_group(sample_condition(sample))] += 1
        lights[str(len(meta.get("lights") or []))] += 1
        median = (meta.get("noise") or {}).get("image", {}).get("median")
        if isinstance(median, int | float):
            noise.append(float(median))
    n_listed = manifest.get("n_samples")
    return ScoredSet(
        dataset=str(dataset.resolve()),
        preset=config.get("preset") if isinstance(config, dict) else None,
        # without a manifest (a sample folder), the samples' own hash when they share one
        config_hash=manifest.get("config_hash")
        or (hashes.pop() if len(hashes) == 1 else None)
        or None,
        n_listed=n_listed if isinstance(n_listed, int) else None,
        n_scored=len(folders),
        groups={g: groups[g] for g in GROUPS if groups[g]},
        lights=dict(sorted(lights.items())),
        noise_median=float(np.median(noise)) if noise else None,
    )


def scored_section(s: ScoredSet) -> list[str]:
    """Markdown lines of the "What was scored" section."""
    listed = f" of the {s.n_listed} it holds" if s.n_listed is not None else ""
    lines = [
        "## What was scored",
        "",
        f"* dataset: `{s.dataset}`",
        f"* preset: `{s.preset or 'not recorded (no manifest.json)'}`; config hash: "
        f"`{s.config_hash or 'not recorded'}`",
        f"* samples scored: {s.n_scored}{listed}",
        "* lighting, measured from each sample's lights (WL: white light, 1L: one coloured "
        "light colour, 2L: two or more light colours): "
        + ", ".join(f"{g} {n}" for g, n in s.groups.items()),
        "* lights per sample: "
        + ", ".join(f"{n} with {k} light{'s' * (k != '1')}" for k, n in s.lights.items()),
    ]
    if s.noise_median is not None:
        lines.append(f"* image noise: median relative standard error {100 * s.noise_median:.1f} %")
    if s.preview_grade:
        lines += [
            "",
            f"**Warning: preview-grade renderings** (preset `{s.preset}`, image noise "
            f"{'n/a' if s.noise_median is None else f'{100 * s.noise_median:.0f} %'}; "
            f"`spectrinsic check` calls a sample noisy above {100 * NOISE_THRESHOLD:.0f} %): "
            "the scores below measure the noise as much as the methods; build with the "
            "default preset before comparing methods.",
        ]
    return [*lines, ""]


def add_scored_section(report: Path, s: ScoredSet) -> None:
    """Insert :func:`scored_section` into *report* after its first paragraph, and write
    ``scored.json`` beside it."""
    text = report.read_text(encoding="utf-8")
    head, sep, rest = text.partition("\n\n## ")
    section = "\n".join(scored_section(s))
    tail = "\n## " + rest if sep else ""
    write_text_file(report, f"{head}\n\n{section}{tail}".rstrip("\n") + "\n")
    record = {**asdict(s), "preview_grade": s.preview_grade}
    write_text_file(
        report.parent / "scored.json", json.dumps(record, indent=1, sort_keys=True) + "\n"
    )
