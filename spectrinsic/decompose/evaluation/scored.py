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
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...file_writes import write_text_file
from ...gt_export.dataset.check import NOISE_THRESHOLD
from ...gt_export.sample import MANIFEST_NAME
from ...gt_export.sample.working_view import space_of
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

    #: The dataset folder's name (no absolute path is written; the config hash identifies it).
    dataset: str
    preset: str | None
    config_hash: str | None
    n_listed: int | None
    n_scored: int
    groups: dict[str, int]
    lights: dict[str, int]
    noise_median: float | None
    #: Each scored sample's lighting group (WL/1L/2L), by sample folder name.
    lighting: dict[str, str] = field(default_factory=dict)
    #: The samples' working spaces (colour-science names) and each one's perfect white under
    #: D65 (``meta.json["working_space"]["white_d65"]``).
    working_spaces: dict[str, list[float]] = field(default_factory=dict)

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


def _manifest_of(dataset: Path) -> dict[str, Any]:
    """The ``manifest.json`` of *dataset*, or of the dataset a sample folder lies in (its
    parent, when that manifest lists the folder); ``{}`` when there is none."""
    if (dataset / MANIFEST_NAME).is_file():
        return _json(dataset / MANIFEST_NAME)
    parent = dataset.resolve().parent / MANIFEST_NAME
    if parent.is_file():
        manifest = _json(parent)
        if dataset.resolve().name in (manifest.get("samples") or {}):
            return manifest
    return {}


def describe_scored(dataset: Path, folders: Sequence[Path]) -> ScoredSet:
    """The :class:`ScoredSet` of the sample *folders* of *dataset* (a dataset folder, or a
    sample folder itself); reads ``manifest.json`` when there is one (for a sample folder, its
    dataset's) and each ``meta.json``."""
    manifest = _manifest_of(dataset)
    config = manifest.get("config") if isinstance(manifest.get("config"), dict) else {}
    groups: Counter[str] = Counter()
    lights: Counter[str] = Counter()
    noise = []
    hashes = set()
    lighting: dict[str, str] = {}
    spaces: dict[str, list[float]] = {}
    for folder in folders:
        meta = _json(folder / "meta.json")
        hashes.add(meta.get("config_hash") if isinstance(meta.get("config_hash"), str) else "")
        # the evaluation's own grouping; refuses a sample it could not group, before any work
        sample = {"meta": {"sample_id": folder.name, **meta}}
        lighting[folder.name] = condition_group(sample_condition(sample))
        space = space_of(meta)
        spaces[space.colourspace] = [round(float(v), 4) for v in space.white]
        groups[lighting[folder.name]] += 1
        lights[str(len(meta.get("lights") or []))] += 1
        median = (meta.get("noise") or {}).get("image", {}).get("median")
        if isinstance(median, int | float):
            noise.append(float(median))
    n_listed = manifest.get("n_samples")
    return ScoredSet(
        dataset=dataset.resolve().name,  # no path of the machine in the REPORT
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
        lighting=lighting,
        working_spaces=spaces,
    )


def scored_section(s: ScoredSet) -> list[str]:
    """Markdown lines of the "What was scored" section."""
    listed = f" of the {s.n_listed} it holds" if s.n_listed is not None else ""
    lines = [
        "## What was scored",
        "",
        f"* dataset: `{s.dataset}`",
        f"* preset: `{s.preset or 'not recorded (no manifest.json with the samples)'}`; config hash: "
        f"`{s.config_hash or 'not recorded'}`",
        f"* samples scored: {s.n_scored}{listed}",
        "* lighting, measured from each sample's lights (WL: white light, 1L: one coloured "
        "light colour, 2L: two or more light colours): "
        + ", ".join(f"{g} {n}" for g, n in s.groups.items()),
        "* working space of the samples: "
        + "; ".join(
            f"{name}, perfect white under D65 = ({', '.join(f'{v:.3f}' for v in white)})"
            for name, white in s.working_spaces.items()
        )
        + " (scored in their linear sRGB view, where that white is (1, 1, 1))",
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
