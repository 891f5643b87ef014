"""The evaluation's summary figure: a method x lighting-condition heatmap of one metric.

Drawn by :func:`spectrinsic.decompose.report.write_report` as ``summary.png`` and embedded in
``REPORT.md``; each cell holds the number of the report's first table, printed in the cell.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ...file_writes import replacing

__all__ = ["SUMMARY_FIGURE", "summary_heatmap"]

#: File name of the summary figure inside the evaluation folder.
SUMMARY_FIGURE = "summary.png"


def summary_heatmap(
    path: Path,
    rows: Sequence[Mapping[str, Any]],
    conditions: Sequence[str],
    *,
    title: str,
    better: str = "lower",
) -> Path:
    """Draw ``rows`` (one per method, ``row["method"]`` and one float per condition) as a
    heatmap with the value printed in every cell; write it to *path* (PNG) and return *path*.

    Colours run over log10 of the values when every finite one is positive (errors span
    decades), else over the values; the best cell of each column is outlined. Drawn with
    matplotlib's object API (no pyplot, so no global backend state).
    """
    from matplotlib.figure import Figure

    data = np.array([[float(r[c]) for c in conditions] for r in rows], dtype=np.float64)
    finite = np.isfinite(data)
    use_log = bool(finite.any() and (data[finite] > 0).all())
    shown = np.where(
        finite, np.log10(np.where(finite & (data > 0), data, 1.0)) if use_log else data, np.nan
    )
    fig = Figure(figsize=(1.6 + 1.3 * len(conditions), 0.9 + 0.45 * len(rows)))
    ax = fig.subplots()
    image = ax.imshow(
        np.ma.masked_invalid(shown),
        cmap="viridis_r" if better == "lower" else "viridis",
        aspect="auto",
    )
    ax.set_xticks(range(len(conditions)), list(conditions), fontsize=8)
    ax.set_yticks(range(len(rows)), [str(r["method"]) for r in rows], fontsize=8)
    for i in range(data.shape[0]):
        for j in range(data.shape[1]):
            text = f"{data[i, j]:.3g}" if finite[i, j] else "—"
            ax.text(
                j, i, text, ha="center", va="center", fontsize=7, color=_ink(image, shown[i, j])
            )
    for j in range(data.shape[1]):
        if finite[:, j].any():
            col = np.where(finite[:, j], data[:, j], np.inf if better == "lower" else -np.inf)
            i = int(np.argmin(col) if better == "lower" else np.argmax(col))
            ax.add_patch(_outline(j, i))
    bar = fig.colorbar(image, ax=ax)
    bar.set_label("log10 of the value" if use_log else "value", fontsize=8)
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=100, metadata={"Software": None})
    return path


def _ink(image: Any, value: float) -> str:
    """Black on light cells, white on dark ones (Rec. 709 luminance of the cell's colour)."""
    if not np.isfinite(value):
        return "black"
    r, g, b, _ = image.cmap(image.norm(value))
    return "black" if 0.2126 * r + 0.7152 * g + 0.0722 * b > 0.45 else "white"


def _outline(x: int, y: int) -> Any:
    from matplotlib.patches import Rectangle

    return Rectangle((x - 0.5, y - 0.5), 1, 1, fill=False, edgecolor="red", linewidth=2)
