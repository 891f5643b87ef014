"""Writing result files: JSON records (with provenance) and CSV tables.

The one home of the result writers of the studies, the benchmarks and the evaluation: every
JSON record and CSV table they write goes through :func:`write_json` and :func:`write_csv`.
Folders are created as needed; text is UTF-8.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from .errors import SpectrinsicError
from .file_writes import replacing, write_text_file
from .provenance import provenance

__all__ = ["write_json", "write_csv", "json_safe", "provenance"]


def write_json(
    path: Path,
    payload: Mapping[str, Any],
    *,
    strict: bool = True,
    default: Callable[[Any], Any] | None = None,
    end: str = "\n",
) -> Path:
    """Write *payload* as JSON indented by 2, creating parent folders; return *path*.

    Parameters
    ----------
    strict
        Refuse NaN and infinities (``ValueError``), so the file is standard JSON; pass the
        payload through :func:`json_safe` first to write them as ``null``.
    default
        Conversion of values JSON cannot represent (e.g. ``str``); None: refuse them.
    end
        Text after the document (a newline; ``""`` for none).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(payload, indent=2, allow_nan=not strict, default=default)
    write_text_file(path, text + end)
    return path


def write_csv(
    path: Path,
    rows: Sequence[Mapping[str, Any]],
    *,
    columns: Sequence[str] | None = None,
    float_format: str | None = None,
) -> Path:
    """Write dict rows as CSV with a header line, creating parent folders; return *path*.

    Parameters
    ----------
    columns
        Header and column order; default: the keys of the first row (then *rows* must not be
        empty). Every row must have exactly these keys.
    float_format
        Format spec of float cells (e.g. ``".6g"``); default: Python's ``str`` (round-trip).
    """
    path = Path(path)
    if columns is None:
        if not rows:
            raise SpectrinsicError(f"{path.name}: no rows and no columns to write")
        columns = list(rows[0])
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as tmp, tmp.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(columns))
        writer.writeheader()
        for row in rows:
            if float_format is not None:
                row = {
                    k: (format(v, float_format) if isinstance(v, float) else v)
                    for k, v in row.items()
                }
            writer.writerow(row)
    return path


def json_safe(value: Any) -> Any:
    """*value* with every non-finite float (in nested dicts and lists) replaced by None."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, list):
        return [json_safe(v) for v in value]
    return value
