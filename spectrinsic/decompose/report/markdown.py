"""``REPORT.md`` of an evaluation: the tables inline, with their numbers, arrows and the best
value of each column in bold, every abbreviation defined once, and the summary figure.

The numbers are those of the CSV tables :mod:`spectrinsic.decompose.report` writes beside it
(the same rows, printed to four significant digits), so a reader never opens another file to
see a result. Scale-invariant global metrics (Corr., si-MSE) sit in their own table, apart
from the local ones (LMSE, aLMSE): si-MSE is in squared units of the layer (shading is
radiometric, so its values can be in the hundreds) while LMSE is normalised by the truth's
local energy, and the two cannot be read side by side.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...scenes.lighting import SAME_COLOUR_XY, WHITE_XY_TOLERANCE
from ..evaluation.photometric import SCENARIOS
from ..evaluation.scores import SCORED_LAYERS

__all__ = ["Column", "GLOSSARY", "markdown_table", "glossary_section", "fmt_number"]

#: Every abbreviation the report uses, defined once (its "Abbreviations" section).
GLOSSARY: tuple[tuple[str, str], ...] = (
    (
        "WL",
        "white light, measured from each sample's lights: one light colour within "
        f"{WHITE_XY_TOLERANCE:g} of D65 in CIE 1931 xy (the library's `white` condition)",
    ),
    (
        "1L",
        "one coloured light, measured: one light colour, further than "
        f"{WHITE_XY_TOLERANCE:g} from D65 in xy (the library's `one-colour` condition)",
    ),
    (
        "2L",
        f"two or more light colours, measured: lights more than {SAME_COLOUR_XY:g} apart in xy "
        "(the library's `two-colour-a` and `two-colour-b` conditions)",
    ),
    ("all", "every lighting condition together"),
    ("refl.", "reflectance (`reflectance`, linear sRGB under D65, in colour)"),
    ("grey shad.", "grey shading (`shading_grey`: luminance Y of the irradiance)"),
    ("col. shad.", "coloured shading (`shading`: linear-sRGB colour of the irradiance)"),
    (
        "LMSE",
        "local mean squared error, thesis Eq. 2.5 (Grosse et al. 2009): a scale fitted in "
        "each 20-pixel window, normalised by the truth's energy; 0 is perfect",
    ),
    ("aLMSE", "absolute LMSE, thesis Eq. 2.6: LMSE after removing each window's mean"),
    (
        "si-MSE",
        "scale-invariant mean squared error, thesis Eq. 2.4: one scale fitted to the whole "
        'image; in squared units of the layer, not normalised (the thesis\' "MSE")',
    ),
    ("Corr.", "Pearson correlation with the truth, thesis Eq. 2.7; 1 is perfect"),
    (
        "shad. chroma (°)",
        "angle between the estimated and true shading colours (Eq. 4.31 on shading), degrees",
    ),
    ("refl. intensity", "reflectance intensity error (MAW, Wu et al. 2023)"),
    ("refl. chroma (°)", "reflectance chromaticity error (MAW, Wu et al. 2023; Eq. 4.31), degrees"),
    *((name, f"photometric scenario: {text}") for name, text in SCENARIOS.items()),
    ("↓ / ↑", "lower / higher is better"),
    ("**bold**", "the best value of its column"),
    ("—", "no value (no sample of that group, or the metric is undefined for it)"),
)


@dataclass(frozen=True)
class Column:
    """One column of an inline table: the row key, its header and which way is better."""

    key: str
    header: str
    better: str = ""  # "lower", "higher" or "" (a label column)

    @property
    def title(self) -> str:
        arrow = {"lower": " ↓", "higher": " ↑"}.get(self.better, "")
        return f"{self.header}{arrow}"


def fmt_number(value: Any) -> str:
    """A table cell: floats to four significant digits (``—`` when not finite), else text.

    >>> fmt_number(0.012345), fmt_number(441.27), fmt_number(float("nan")), fmt_number("x")
    ('0.01235', '441.3', '—', 'x')
    """
    if isinstance(value, float | np.floating):
        return f"{float(value):.4g}" if np.isfinite(value) else "—"
    return str(value)


def _best(rows: Sequence[Mapping[str, Any]], col: Column) -> float | None:
    values = [
        float(r[col.key])
        for r in rows
        if isinstance(r.get(col.key), float | np.floating) and np.isfinite(r[col.key])
    ]
    if not col.better or len(values) < 2:
        return None
    return min(values) if col.better == "lower" else max(values)


def markdown_table(rows: Sequence[Mapping[str, Any]], columns: Sequence[Column]) -> str:
    """A Markdown table of *rows*, the best value of every scored column in bold (when two or
    more rows have one; ties all bold, compared as printed)."""
    best = {c.key: _best(rows, c) for c in columns}
    lines = ["| " + " | ".join(c.title for c in columns) + " |", "|" + "---|" * len(columns)]
    for r in rows:
        cells = []
        for c in columns:
            text = fmt_number(r.get(c.key, float("nan")))
            top = best[c.key]
            cells.append(f"**{text}**" if top is not None and text == fmt_number(top) else text)
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def glossary_section() -> list[str]:
    """The "Abbreviations" section: a two-column table, each term once."""
    lines = ["## Abbreviations", "", "| term | meaning |", "|---|---|"]
    lines += [f"| {term} | {text} |" for term, text in GLOSSARY]
    lines += ["", "Layers scored:", ""] + [f"* `{k}`: {v}" for k, v in SCORED_LAYERS.items()]
    return lines + [""]
