"""A dataset source as it is recorded and hashed: no path of the machine that built it.

A files source (``dataset --scenes``, ``render --ground-truth FILE``) holds, in memory, the
absolute paths of its scene files, which the build reads. What a dataset records
(``manifest.json``, every ``meta.json``'s config, ``DATASET.md``) and what its config hash is
taken of is :func:`recorded_source`: each scene file by its name and SHA-256, and every
``csv:`` spectrum of the material map or default spectrum by its file name
(:func:`~spectrinsic.spectra.user_spectra.portable_csv`). The same scene files built from
another folder or machine then give the same config and hash, so a rerun there resumes the
set, and no written file leaks the builder's file system.
"""

from __future__ import annotations

import json
from pathlib import PurePath
from typing import Any

from ..spectra.user_spectra import portable_names

__all__ = ["recorded_source"]


def _recorded_entry(entry: Any) -> Any:
    if isinstance(entry, dict) and isinstance(entry.get("path"), str):
        return {**entry, "path": PurePath(entry["path"]).name}
    return entry


def recorded_source(source: str) -> str:
    """The canonical JSON *source* as recorded and hashed (module docstring); a generated or
    library source unchanged."""
    spec = json.loads(source)
    if not isinstance(spec, dict) or "scenes" not in spec:
        return source
    spec = portable_names({k: v for k, v in spec.items() if k != "scenes"})
    spec["scenes"] = [_recorded_entry(e) for e in json.loads(source)["scenes"]]
    return json.dumps(spec, sort_keys=True, allow_nan=False)
