"""``REPORT.md`` and ``mit_lmse.png`` of an MIT-protocol evaluation (``evaluate --mit``).

The report says what was scored (the folder, how many objects, which methods), holds thesis
Table 3.2's rows (:func:`spectrinsic.decompose.evaluation.mit.mit_markdown`) and explains every column;
the figure is the mean LMSE per method (lower is better).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ...file_writes import replacing, write_text_file
from ..evaluation.mit import MEASURES, mit_markdown

__all__ = ["COLUMNS", "MIT_FIGURE", "write_mit_report"]

#: The figure beside the report.
MIT_FIGURE = "mit_lmse.png"
#: Every column of the table and what it holds.
COLUMNS: tuple[tuple[str, str], ...] = (
    ("method", "the decomposer, or a predictions folder (--predictions)"),
    ("objects", "MIT objects scored"),
    (
        "Corr.",
        "correlation of estimate and ground truth, mean of shading and reflectance "
        "(higher is better)",
    ),
    ("MSE", "scale-invariant mean squared error, mean of shading and reflectance"),
    ("LMSE", "local MSE over 20x20 windows (Grosse et al. 2009), the MIT benchmark's score"),
    ("aLMSE", "absolute LMSE: local MSE without the per-window scale"),
    (
        "beats baseline",
        "objects on which the method's LMSE is lower than that of "
        "`image-as-reflectance` (the baseline that returns the input as reflectance); "
        "shown when the baseline was scored",
    ),
)


def _numbers(row: Mapping[str, Any]) -> dict[str, Any]:
    """A table row with its measures as floats and its counts as integers."""
    out = dict(row)
    for key in MEASURES:
        out[key] = float(out[key])
    out["objects"] = int(out["objects"])
    if out.get("beats_baseline") not in (None, ""):
        out["beats_baseline"] = int(out["beats_baseline"])
    else:
        out.pop("beats_baseline", None)
    return out


def _figure(path: Path, rows: Sequence[Mapping[str, Any]]) -> None:
    from matplotlib.figure import Figure  # no pyplot: no global backend state

    fig = Figure(figsize=(6.0, 0.5 + 0.35 * len(rows)))
    ax = fig.subplots()
    names = [str(r["method"]) for r in rows]
    ax.barh(names, [float(r["lmse"]) for r in rows], color="#4c72b0")
    ax.invert_yaxis()
    ax.set_xlabel("mean LMSE over objects (lower is better)")
    fig.tight_layout()
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=100)


def write_mit_report(
    out: Path, folder: Path, n_objects: int, rows: Sequence[Mapping[str, Any]]
) -> dict[str, Path]:
    """Write ``REPORT.md`` and :data:`MIT_FIGURE` under *out* from the table's *rows* (as
    :func:`~spectrinsic.decompose.evaluation.mit.mit_table` gives them, or as read back from
    ``mit_table_3_2.csv``: text cells are converted); return their paths."""
    rows = [_numbers(r) for r in rows]
    figure = out / MIT_FIGURE
    _figure(figure, rows)
    md = [
        "# MIT intrinsic images: thesis Table 3.2",
        "",
        "## What was scored",
        "",
        f"* folder: `{folder.resolve().name}` (the MIT data set's folder)",
        f"* objects: {n_objects}; methods: {', '.join(str(r['method']) for r in rows)}",
        "* protocol: the thesis' (sec. 3.5): grey shading and reflectance, each measure the mean "
        "of the two layers, means over objects",
        "",
        mit_markdown(rows),
        f"![Mean LMSE per method]({MIT_FIGURE})",
        "",
        "## Columns",
        "",
        *(f"* **{name}**: {text}" for name, text in COLUMNS),
        "",
        "Per-object numbers: `mit_scores.csv`; the table as CSV: `mit_table_3_2.csv`.",
    ]
    report = out / "REPORT.md"
    write_text_file(report, "\n".join(md) + "\n")
    return {"report": report, "figure": figure}
