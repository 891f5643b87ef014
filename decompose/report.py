"""Tables and files of an evaluation: scores, Tables 5.1/5.3/5.4 analogues, the report.

Every table says which layer it scores (:data:`spectrinsic.decompose.evaluate.SCORED_LAYERS`):
``reflectance`` in colour, ``shading_grey`` (the thesis' grey shading) and ``shading`` (the
coloured irradiance shading).
"""

from __future__ import annotations

import dataclasses
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from spectrinsic.decompose.metrics import METRICS
from spectrinsic.decompose.photometric import SCENARIOS
from spectrinsic.decompose.registry import DECOMPOSERS
from spectrinsic.decompose.scores import CONDITION_GROUPS, INPUT_LAYERS, SCORED_LAYERS, Score
from spectrinsic.results import write_csv, write_json

__all__ = [
    "LMSE_COLUMNS",
    "COLOUR_COLUMNS",
    "TABLE_3_2_COLUMNS",
    "condition_table",
    "table_3_2",
    "scenario_table",
    "method_parameters",
    "write_report",
]

_GROUP_ORDER = ("WL", "1L", "2L")
_KINDS = {"object": "single objects", "complex": "complex scenes"}
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


def _mean(values: list[float]) -> float:
    finite = [v for v in values if np.isfinite(v)]
    return float(np.mean(finite)) if finite else float("nan")


def _method_order(name: str) -> tuple[int, str]:
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
            groups[(kind, s.method, s.layer, s.metric, CONDITION_GROUPS[cond])].append(s.value)
    rows = []
    for kind in _KINDS:
        for method in sorted({k[1] for k in groups if k[0] == kind}, key=_method_order):
            row: dict[str, Any] = {"scene_kind": kind, "method": method}
            for prefix, layer, metric, _ in columns:
                for g in _GROUP_ORDER:
                    row[f"{prefix}_{g}"] = _mean(groups.get((kind, method, layer, metric, g), []))
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
        for method in sorted({k[1] for k in groups if k[0] == camera}, key=_method_order):
            row: dict[str, Any] = {"camera": camera, "method": method}
            for sc in _PHOTOMETRIC:
                row[sc] = _mean(groups.get((camera, method, sc), []))
            rows.append(row)
    return rows


#: Thesis Table 3.2's columns: (key, metric, header); each the mean over samples of
#: ``(shading_grey + reflectance_grey) / 2``.
TABLE_3_2_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("corr", "corr", "Corr."), ("mse", "si_mse", "MSE"), ("lmse", "lmse", "LMSE"),
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
            for g in (CONDITION_GROUPS[samples[sid][1]], "all"):
                groups[(method, metric, g)].append(value)
    rows = []
    for method in sorted({k[0] for k in groups}, key=_method_order):
        for g in (*_GROUP_ORDER, "all"):
            row: dict[str, Any] = {"method": method, "lighting": g}
            for key, metric, _ in TABLE_3_2_COLUMNS:
                row[key] = _mean(groups.get((method, metric, g), []))
            rows.append(row)
    return rows


def method_parameters(methods: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """``{name: {"class": ..., "parameters": {...}}}`` of each method (dataclass fields)."""
    out = {}
    for name, method in methods.items():
        params = (
            {f.name: getattr(method, f.name) for f in dataclasses.fields(method)}
            if dataclasses.is_dataclass(method) else {}
        )
        out[name] = {
            "class": f"{type(method).__module__}.{type(method).__qualname__}",
            "parameters": {k: (str(v) if isinstance(v, Path) else v) for k, v in params.items()},
        }
    return out


def _write_csv(path: Path, rows: list[dict[str, Any]], columns: Sequence[str]) -> None:
    """A table of the report: floats to 6 significant digits."""
    write_csv(path, rows, columns=columns, float_format=".6g")


def _markdown(rows: list[dict[str, Any]], columns: Sequence[str], headers: Sequence[str]) -> str:
    def fmt(v: Any) -> str:
        return ("—" if not np.isfinite(v) else f"{v:.3f}") if isinstance(v, float) else str(v)

    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(fmt(r[c]) for c in columns) + " |" for r in rows]
    return "\n".join(lines)


def _condition_files(
    out: Path, stem: str, title: str, rows: list[dict[str, Any]],
    columns: Sequence[tuple[str, str, str, str]], note: str = "",
) -> dict[str, Path]:
    keys = [f"{prefix}_{g}" for prefix, *_ in columns for g in _GROUP_ORDER]
    _write_csv(out / f"{stem}.csv", rows, ["scene_kind", "method", *keys])
    layers = sorted({layer for _, layer, _, _ in columns})
    md = [*_titled(title, note), "Mean over samples; sRGB input. Layers scored:", ""]
    md += [f"* `{layer}`: {SCORED_LAYERS[layer]}" for layer in layers]
    md += [f"* {header}: metric `{metric}` ({METRICS[metric].equation}) of `{layer}`"
           for _, layer, metric, header in columns]
    md.append("")
    headers = ["method"] + [f"{h} {g}" for *_, h in columns for g in _GROUP_ORDER]
    for kind, name in _KINDS.items():
        sel = [r for r in rows if r["scene_kind"] == kind]
        if sel:
            md += [f"## {name.capitalize()}", "", _markdown(sel, ["method", *keys], headers), ""]
    (out / f"{stem}.md").write_text("\n".join(md), encoding="utf-8")
    return {f"{stem}_csv": out / f"{stem}.csv", f"{stem}_md": out / f"{stem}.md"}


def _titled(title: str, note: str) -> list[str]:
    """A markdown title and, when there is one, the evaluation target's note below it."""
    return [f"# {title}", "", note, ""] if note else [f"# {title}", ""]


def _report_md(
    methods: Mapping[str, Any], inputs: Sequence[str], n_samples: int, files: Mapping[str, Path],
    note: str = "",
) -> str:
    md = [*_titled("Evaluation report", note), f"{n_samples} samples. Input decomposed: "
          + ", ".join(f"`{k}`" for k in inputs)
          + f" (the first of {list(INPUT_LAYERS)} each sample has).", "", "## Layers scored", ""]
    md += [f"* `{layer}`: {text}" for layer, text in SCORED_LAYERS.items()]
    md += ["", "## Methods and parameters", ""]
    for name, record in method_parameters(methods).items():
        params = ", ".join(f"{k}={v!r}" for k, v in record["parameters"].items() if k != "name")
        md.append(f"* **{name}** (`{record['class']}`): {params or 'no parameters'}")
        protocol = getattr(methods[name], "protocol", "")
        if protocol:
            md.append(f"  * parameters chosen by: {protocol}")
    md += ["", "## Tables", ""] + [f"* `{p.name}`" for p in files.values() if p.suffix == ".md"]
    return "\n".join(md) + "\n"


def write_report(
    out: Path,
    scores: Sequence[Score],
    samples: Mapping[str, tuple[str, str]],
    methods: Mapping[str, Any],
    inputs: Sequence[str],
    note: str = "",
) -> dict[str, Path]:
    """Write ``scores.csv``, the condition and scenario tables, ``methods.json`` and ``REPORT.md``.

    *note* (:func:`spectrinsic.decompose.targets.target_note`) is printed under every title.
    """
    files: dict[str, Path] = {"scores": out / "scores.csv"}
    _write_csv(files["scores"], [
        {"sample": s.sample, "method": s.method, "scenario": s.scenario, "layer": s.layer,
         "metric": s.metric, "value": s.value} for s in scores
    ], ("sample", "method", "scenario", "layer", "metric", "value"))
    files.update(_condition_files(
        out, "lmse_by_condition", "LMSE by lighting condition (like thesis Tables 5.3 and 5.4)",
        condition_table(scores, samples, columns=LMSE_COLUMNS), LMSE_COLUMNS, note))
    files.update(_condition_files(
        out, "colour_by_condition", "Coloured-shading metrics by lighting condition",
        condition_table(scores, samples, columns=COLOUR_COLUMNS), COLOUR_COLUMNS, note))
    scen_rows = scenario_table(scores)
    scen_cols = ["camera", "method", *_PHOTOMETRIC]
    _write_csv(out / "lmse_by_scenario.csv", scen_rows, scen_cols)
    md = _titled("Reflectance LMSE by photometric scenario (like thesis Table 5.1)", note)
    md += [_markdown(scen_rows, scen_cols, scen_cols) if scen_rows
           else "No camera renderings scored: Table 5.1 needs `image_camera/<name>`."]
    (out / "lmse_by_scenario.md").write_text("\n".join(md) + "\n", encoding="utf-8")
    files.update(scenario_csv=out / "lmse_by_scenario.csv", scenario_md=out / "lmse_by_scenario.md")
    t32 = table_3_2(scores, samples)
    cols = ["method", "lighting", *(k for k, _, _ in TABLE_3_2_COLUMNS)]
    _write_csv(out / "table_3_2_objects.csv", t32, cols)
    md = [*_titled("Single objects, like thesis Table 3.2 (MIT-20)", note),
          "Mean over samples of (grey shading + grey reflectance) / 2, grey = mean over "
          "channels, as the thesis (sec. 3.5); MSE is the scale-invariant MSE (Eq. 2.4).", "",
          _markdown(t32, cols, ["method", "light", *(h for _, _, h in TABLE_3_2_COLUMNS)]) if t32
          else "No single-object samples scored."]
    (out / "table_3_2_objects.md").write_text("\n".join(md) + "\n", encoding="utf-8")
    files.update(table_3_2_csv=out / "table_3_2_objects.csv",
                 table_3_2_md=out / "table_3_2_objects.md")
    files["methods"] = out / "methods.json"
    write_json(files["methods"], method_parameters(methods), strict=False, default=str, end="")
    files["report"] = out / "REPORT.md"
    files["report"].write_text(_report_md(methods, inputs, len(samples), files, note), encoding="utf-8")
    return files
