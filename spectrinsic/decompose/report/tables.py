"""The evaluation report's tables as rows: means of the scores per method and group.

Thesis Tables 5.3/5.4 (:func:`condition_table`), 5.1 (:func:`scenario_table`) and 3.2
(:func:`table_3_2`), and the report's summary (:func:`summary_table`);
:mod:`spectrinsic.decompose.report` writes them as CSV and markdown.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from ..evaluation.photometric import SCENARIOS
from ..evaluation.scores import CONDITION_GROUPS, Score, condition_group
from ..methods.registry import DECOMPOSERS

__all__ = [
    "GROUP_ORDER",
    "SCENE_KINDS",
    "LMSE_COLUMNS",
    "COLOUR_COLUMNS",
    "TABLE_3_2_COLUMNS",
    "condition_table",
    "table_3_2",
    "scenario_table",
    "summary_table",
    "mean_finite",
    "method_order",
]

#: The lighting groups of the condition tables, in column order.
GROUP_ORDER = ("WL", "1L", "2L")
#: Scene kinds and their names in the report, in table order.
SCENE_KINDS = {"object": "single objects", "complex": "complex scenes"}
_PHOTOMETRIC = tuple(SCENARIOS)
#: ``(column prefix, layer, metric, header)`` of the LMSE table (thesis Tables 5.3/5.4).
LMSE_COLUMNS: tuple[tuple[str, str, str, str], ...] = (
    ("reflectance", "reflectance", "lmse", "refl."),
    ("shading_grey", "shading_grey", "lmse", "grey shad."),
    ("shading", "shading", "lmse", "col. shad."),
)
#: The coloured-shading metrics: shading chromaticity (degrees) and the MAW-style split.
COLOUR_COLUMNS: tuple[tuple[str, str, str, str], ...] = (
    ("shading_chromaticity", "shading", "shading_chromaticity", "shad. chroma (°)"),
    ("reflectance_intensity", "reflectance", "intensity_error", "refl. intensity"),
    ("reflectance_chromaticity", "reflectance", "chromaticity_error", "refl. chroma (°)"),
)


def mean_finite(values: list[float]) -> float:
    finite = [v for v in values if np.isfinite(v)]
    return float(np.mean(finite)) if finite else float("nan")


def method_order(name: str) -> tuple[int, str]:
    """Bundled methods in registry order, then the others (plugins, predictions) by name."""
    order = list(DECOMPOSERS)
    return (order.index(name) if name in order else len(order), name)


def condition_table(
    scores: Iterable[Score],
    samples: Mapping[str, tuple[str, str]],
    *,
    columns: Sequence[tuple[str, str, str, str]] = LMSE_COLUMNS,
) -> list[dict[str, Any]]:
    """Rows like Tables 5.3/5.4: per scene kind and method, the mean of each column's
    ``(layer, metric)`` over the samples of each lighting group WL/1L/2L (sRGB input).

    ``samples`` maps sample ids to ``(kind, condition)``; column keys are ``<prefix>_<group>``.
    """
    wanted = {(layer, metric) for _, layer, metric, _ in columns}
    groups: dict[tuple[str, str, str, str, str], list[float]] = defaultdict(list)
    for s in scores:
        if s.scenario == "srgb" and (s.layer, s.metric) in wanted:
            kind, cond = samples[s.sample]
            groups[(kind, s.method, s.layer, s.metric, condition_group(cond))].append(s.value)
    rows = []
    for kind in SCENE_KINDS:
        for method in sorted({k[1] for k in groups if k[0] == kind}, key=method_order):
            row: dict[str, Any] = {"scene_kind": kind, "method": method}
            for prefix, layer, metric, _ in columns:
                for g in GROUP_ORDER:
                    row[f"{prefix}_{g}"] = mean_finite(
                        groups.get((kind, method, layer, metric, g), [])
                    )
            rows.append(row)
    return rows


def scenario_table(scores: Iterable[Score], *, metric: str = "lmse") -> list[dict[str, Any]]:
    """Rows like Table 5.1: mean reflectance *metric* per method, camera and SC1/SC3b/SC4."""
    groups: dict[tuple[str, str, str], list[float]] = defaultdict(list)
    for s in scores:
        if s.camera and s.layer == "reflectance" and s.metric == metric:
            groups[(s.camera, s.method, s.photometric)].append(s.value)
    rows = []
    for camera in sorted({k[0] for k in groups}):
        for method in sorted({k[1] for k in groups if k[0] == camera}, key=method_order):
            row: dict[str, Any] = {"camera": camera, "method": method}
            for sc in _PHOTOMETRIC:
                row[sc] = mean_finite(groups.get((camera, method, sc), []))
            rows.append(row)
    return rows


#: Thesis Table 3.2's columns: (key, metric, header); each the mean over samples of
#: ``(shading_grey + reflectance_grey) / 2``.
TABLE_3_2_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("corr", "corr", "Corr."),
    ("mse", "si_mse", "MSE"),
    ("lmse", "lmse", "LMSE"),
    ("almse", "almse", "aLMSE"),
)


def table_3_2(
    scores: Iterable[Score], samples: Mapping[str, tuple[str, str]], *, kind: str = "object"
) -> list[dict[str, Any]]:
    """Rows like thesis Table 3.2 on the samples of *kind*: per method and lighting group (and
    ``"all"``), the mean over samples of ``(shading_grey + reflectance_grey) / 2`` of each
    metric, grey layers as the thesis (sec. 3.5)."""
    per: dict[tuple[str, str, str], dict[str, list[float]]] = defaultdict(lambda: defaultdict(list))
    for s in scores:
        if s.scenario == "srgb" and s.layer in ("shading_grey", "reflectance_grey"):
            k, cond = samples[s.sample]
            if k == kind:
                per[(s.method, s.metric, s.sample)][s.layer].append(s.value)
    groups: dict[tuple[str, str, str], list[float]] = defaultdict(list)
    for (method, metric, sid), layers in per.items():
        if len(layers) == 2:
            value = 0.5 * (layers["shading_grey"][0] + layers["reflectance_grey"][0])
            for g in (condition_group(samples[sid][1]), "all"):
                groups[(method, metric, g)].append(value)
    rows = []
    for method in sorted({k[0] for k in groups}, key=method_order):
        for g in (*GROUP_ORDER, "all"):
            row: dict[str, Any] = {"method": method, "lighting": g}
            for key, metric, _ in TABLE_3_2_COLUMNS:
                row[key] = mean_finite(groups.get((method, metric, g), []))
            rows.append(row)
    return rows


def summary_table(
    scores: Iterable[Score], samples: Mapping[str, tuple[str, str]]
) -> list[dict[str, Any]]:
    """Rows of the report's first table and summary figure: per method, the mean reflectance
    LMSE (sRGB input) over the samples of each lighting condition present, and over all."""
    per: dict[tuple[str, str], list[float]] = defaultdict(list)
    for s in scores:
        if s.scenario == "srgb" and s.layer == "reflectance" and s.metric == "lmse":
            per[(s.method, samples[s.sample][1])].append(s.value)
            per[(s.method, "all")].append(s.value)
    conditions = [c for c in (*CONDITION_GROUPS, *GROUP_ORDER) if any(k[1] == c for k in per)]
    return [
        {"method": m, **{c: mean_finite(per.get((m, c), [])) for c in (*conditions, "all")}}
        for m in sorted({k[0] for k in per}, key=method_order)
    ]
