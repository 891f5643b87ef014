"""The dataset's sample plan: the tasks of the default layout or of a source, and ``--only``.

:func:`plan_samples` lists the :class:`~spectrinsic.pipeline.tasks.SampleTask` of every sample
a dataset build makes; :func:`select_samples` keeps those matching the glob patterns of
``--only``.
"""

from __future__ import annotations

import fnmatch
import os
from collections.abc import Sequence
from pathlib import Path

from ..errors import DatasetError
from ..scenes.library import default_samples, glossy_samples
from .presets import DatasetConfig
from .source_plan import plan_source_samples
from .tasks import SampleTask

__all__ = ["plan_samples", "select_samples"]


def plan_samples(
    out_dir: str | os.PathLike[str],
    config: DatasetConfig,
    *,
    only: Sequence[str] | str | None = None,
    data_dir: str | os.PathLike[str] | None = None,
    render_threads: int | None = None,
) -> list[SampleTask]:
    """The tasks of the default sample layout (68 samples), optionally filtered by *only*.

    Parameters
    ----------
    only
        Glob pattern(s) on the sample id (``"obj-*"``, ``"*__white"``); a string may hold
        several separated by commas. ``None`` keeps every sample. A pattern holding
        ``glossy`` also selects among the glossy variants (``room-living-glossy__v0__white``).

    Raises
    ------
    DatasetError
        If *only* matches no sample.
    """
    out = str(Path(out_dir))
    if config.source is not None:
        tasks = plan_source_samples(
            out,
            config,
            render_threads=render_threads,
            data_dir=None if data_dir is None else str(data_dir),
        )
        return select_samples(tasks, only)
    tasks = [
        SampleTask.planned(
            sid,
            config,
            out,
            render_threads=render_threads,
            data_dir=None if data_dir is None else str(data_dir),
        )
        for sid in default_samples() + (glossy_samples() if _asks_glossy(only) else [])
    ]
    return select_samples(tasks, only)


def _asks_glossy(only: Sequence[str] | str | None) -> bool:
    """Whether an *only* pattern names the library's glossy variants (``*-glossy*``), which the
    default layout leaves out."""
    patterns = only.split(",") if isinstance(only, str) else list(only or ())
    return any("glossy" in p for p in patterns)


def select_samples(
    specs: Sequence[SampleTask], only: Sequence[str] | str | None
) -> list[SampleTask]:
    """Keep the tasks whose ``sample_id`` matches one of the glob patterns *only*."""
    if only is None:
        return list(specs)
    patterns = [p.strip() for p in only.split(",")] if isinstance(only, str) else list(only)
    patterns = [p for p in patterns if p]
    kept = [s for s in specs if any(fnmatch.fnmatchcase(s.sample_id, p) for p in patterns)]
    if not kept:
        raise DatasetError(
            f"--only {','.join(patterns)!r} matches no sample; ids look like {specs[0].sample_id!r}"
            if specs
            else "no samples to select from"
        )
    return kept
