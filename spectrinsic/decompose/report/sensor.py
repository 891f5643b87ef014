"""The camera-chain table of ``REPORT.md``: each method on a camera's processed image.

Samples built with ``dataset --camera NAME`` are scored in the scenario ``sensor_<camera>``
(:mod:`spectrinsic.decompose.evaluation.processed`): the method gets the chain's processed linear
image, noise included (``image_sensor_noisy/<camera>``), and its estimates are scored against the
ground truth carried through the same linear stages (``reflectance_sensor/<camera>``,
``shading_sensor/<camera>``). This table gives the mean over samples of each column's metric.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable, Sequence
from typing import Any

from ..evaluation.scores import Score
from .markdown import Column, markdown_table
from .tables import mean_finite, method_order

__all__ = ["SENSOR_PREFIX", "SENSOR_COLUMNS", "sensor_table", "sensor_md"]

#: Scenario-name prefix of the camera-chain scores.
SENSOR_PREFIX = "sensor_"
#: The table's columns: (key, layer, metric, header).
SENSOR_COLUMNS: tuple[tuple[str, str, str, str], ...] = (
    ("refl_lmse", "reflectance", "lmse", "refl. LMSE"),
    ("refl_mse", "reflectance", "si_mse", "refl. si-MSE"),
    ("grey_lmse", "shading_grey", "lmse", "grey shad. LMSE"),
    ("grey_mse", "shading_grey", "si_mse", "grey shad. si-MSE"),
    ("col_lmse", "shading", "lmse", "col. shad. LMSE"),
)


def sensor_table(scores: Iterable[Score]) -> list[dict[str, Any]]:
    """One row per camera-chain scenario and method: the mean of each :data:`SENSOR_COLUMNS`
    metric over the samples."""
    wanted = {(layer, metric): key for key, layer, metric, _ in SENSOR_COLUMNS}
    groups: dict[tuple[str, str, str], list[float]] = defaultdict(list)
    for s in scores:
        key = wanted.get((s.layer, s.metric))
        if key is not None and s.scenario.startswith(SENSOR_PREFIX):
            groups[(s.scenario, s.method, key)].append(s.value)
    rows = []
    for scenario in sorted({k[0] for k in groups}):
        for method in sorted({k[1] for k in groups if k[0] == scenario}, key=method_order):
            row: dict[str, Any] = {"camera": scenario.removeprefix(SENSOR_PREFIX), "method": method}
            for key, *_ in SENSOR_COLUMNS:
                row[key] = mean_finite(groups.get((scenario, method, key), []))
            rows.append(row)
    return rows


def sensor_md(rows: Sequence[dict[str, Any]]) -> list[str]:
    """The REPORT section (an empty list when no sample went through a camera chain)."""
    if not rows:
        return []
    cols = [
        Column("camera", "camera"),
        Column("method", "method"),
        *(Column(key, header, "lower") for key, _, _, header in SENSOR_COLUMNS),
    ]
    return [
        "## Camera chain: the processed image (`dataset --camera`)",
        "",
        "Each method decomposes the chain's processed linear image (noise, demosaicking, white "
        "balance and colour matrix included) and is scored against the ground truth carried "
        "through the same linear stages; mean over samples. Per sample: `scores.csv`, scenario "
        "`sensor_<camera>`.",
        "",
        markdown_table(rows, cols),
        "",
    ]
