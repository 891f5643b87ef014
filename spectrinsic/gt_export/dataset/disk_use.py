"""The bytes a built dataset holds, measured from its sample folders.

Each sample folder's bytes are the sizes of its regular files (``st_size``: the bytes written,
not the disk blocks they occupy; symbolic links are neither followed nor counted), split into
the data and the PNG previews under ``previews/`` (for looking only, so counted apart). A set
that mixes samples with and without the per-light transport (``--store-transport``) or the
band layers (``--spectral-layers``) is also summarised by kind, as their sizes differ several
fold. The folder's own files (``manifest.json``, ``DATASET.md``, the gallery) are not counted.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..layers.spectral_intrinsics import SPECTRAL_GROUP
from ..sample import PREVIEW_DIR
from ..sample.transport_exr import TRANSPORT_NAME

__all__ = ["PROJECTED_SAMPLES", "ByteStats", "SampleBytes", "DiskUse", "disk_use", "sample_kind"]

#: The set size the card projects to: 10,000 samples.
PROJECTED_SAMPLES = 10_000


@dataclass(frozen=True)
class ByteStats:
    """Bytes per sample over a group of samples (``samples`` ≥ 1)."""

    samples: int
    total: int
    smallest: int
    largest: int

    @property
    def mean(self) -> float:
        """Mean bytes per sample."""
        return self.total / self.samples

    @property
    def projected(self) -> float:
        """Bytes of :data:`PROJECTED_SAMPLES` samples like these: a projection,
        ``PROJECTED_SAMPLES`` × :attr:`mean`, not a measurement."""
        return PROJECTED_SAMPLES * self.mean

    @classmethod
    def of(cls, values: Sequence[int]) -> ByteStats:
        """The statistics of per-sample byte counts *values* (at least one)."""
        return cls(
            samples=len(values), total=sum(values), smallest=min(values), largest=max(values)
        )


@dataclass(frozen=True)
class SampleBytes:
    """One sample folder's bytes: its data files and its ``previews/`` apart."""

    sample_id: str
    kind: str
    data: int
    previews: int


@dataclass(frozen=True)
class DiskUse:
    """The sample folders' bytes, per sample (sorted by id)."""

    samples: tuple[SampleBytes, ...]

    @property
    def data(self) -> ByteStats:
        """Bytes per sample without previews."""
        return ByteStats.of([s.data for s in self.samples])

    @property
    def previews(self) -> ByteStats:
        """Bytes of the PNG previews per sample."""
        return ByteStats.of([s.previews for s in self.samples])

    @property
    def total(self) -> int:
        """Bytes of every sample folder, previews included."""
        return sum(s.data + s.previews for s in self.samples)

    @property
    def by_kind(self) -> Mapping[str, ByteStats]:
        """Bytes per sample without previews, per :func:`sample_kind`, sorted by kind."""
        kinds = sorted({s.kind for s in self.samples})
        return {k: ByteStats.of([s.data for s in self.samples if s.kind == k]) for k in kinds}


def sample_kind(folder: Path) -> str:
    """What makes a sample large: ``"transport and spectral layers"``, ``"transport"``,
    ``"spectral layers"`` or ``"plain"`` (neither file)."""
    parts = [
        name
        for name, file in (
            ("transport", TRANSPORT_NAME),
            ("spectral layers", f"{SPECTRAL_GROUP}.exr"),
        )
        if (folder / file).is_file()
    ]
    return " and ".join(parts) or "plain"


def _folder_bytes(folder: Path) -> tuple[int, int]:
    """``(data bytes, preview bytes)`` of the regular files under *folder*."""
    data = previews = 0
    for here, dirs, files in os.walk(folder):  # does not descend into linked folders
        dirs.sort()
        in_previews = Path(here).relative_to(folder).parts[:1] == (PREVIEW_DIR,)
        for name in files:
            info = os.lstat(os.path.join(here, name))
            if not stat.S_ISREG(info.st_mode):
                continue
            if in_previews:
                previews += info.st_size
            else:
                data += info.st_size
    return data, previews


def disk_use(samples: Sequence[Path]) -> DiskUse:
    """The bytes of the sample folders *samples* (at least one)."""
    if not samples:
        raise ValueError("disk_use: expected at least one sample folder")
    records = []
    for folder in sorted(samples):
        data, previews = _folder_bytes(folder)
        records.append(SampleBytes(folder.name, sample_kind(folder), data, previews))
    return DiskUse(samples=tuple(records))
