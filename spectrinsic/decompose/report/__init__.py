"""Tables and files of an evaluation: scores, Tables 5.1/5.3/5.4 analogues, the report.

Every table says which layer it scores (:data:`spectrinsic.decompose.evaluation.evaluate.SCORED_LAYERS`):
``reflectance`` in colour, ``shading_grey`` (the thesis' grey shading) and ``shading`` (the
coloured irradiance shading).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ...file_writes import write_text_file
from ...results import write_csv, write_json
from ..evaluation.evaluate import EvaluationResult
from ..evaluation.photometric import SCENARIOS
from ..evaluation.scores import INPUT_LAYERS, SCORED_LAYERS, condition_group
from ..metrics import METRICS
from .figure import SUMMARY_FIGURE, summary_heatmap
from .markdown import Column, glossary_section, markdown_table
from .sensor import sensor_md, sensor_table
from .tables import (
    COLOUR_COLUMNS,
    GROUP_ORDER,
    LMSE_COLUMNS,
    SCENE_KINDS,
    TABLE_3_2_COLUMNS,
    condition_table,
    scenario_table,
    summary_table,
    table_3_2,
)

__all__ = [
    "method_parameters",
    "write_report",
]

_PHOTOMETRIC = tuple(SCENARIOS)


def method_parameters(methods: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """``{name: {"class": ..., "parameters": {...}}}`` of each method (dataclass fields)."""
    out = {}
    for name, method in methods.items():
        params = (
            {f.name: getattr(method, f.name) for f in dataclasses.fields(method)}
            if dataclasses.is_dataclass(method)
            else {}
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
    out: Path,
    stem: str,
    title: str,
    rows: list[dict[str, Any]],
    columns: Sequence[tuple[str, str, str, str]],
    note: str = "",
) -> dict[str, Path]:
    keys = [f"{prefix}_{g}" for prefix, *_ in columns for g in GROUP_ORDER]
    _write_csv(out / f"{stem}.csv", rows, ["scene_kind", "method", *keys])
    layers = sorted({layer for _, layer, _, _ in columns})
    md = [*_titled(title, note), "Mean over samples; sRGB input. Layers scored:", ""]
    md += [f"* `{layer}`: {SCORED_LAYERS[layer]}" for layer in layers]
    md += [
        f"* {header}: metric `{metric}` ({METRICS[metric].equation}) of `{layer}`"
        for _, layer, metric, header in columns
    ]
    md.append("")
    headers = ["method"] + [f"{h} {g}" for *_, h in columns for g in GROUP_ORDER]
    for kind, name in SCENE_KINDS.items():
        sel = [r for r in rows if r["scene_kind"] == kind]
        if sel:
            md += [f"## {name.capitalize()}", "", _markdown(sel, ["method", *keys], headers), ""]
    write_text_file(out / f"{stem}.md", "\n".join(md))
    return {f"{stem}_csv": out / f"{stem}.csv", f"{stem}_md": out / f"{stem}.md"}


def _group_columns(columns: Sequence[tuple[str, str, str, str]]) -> list[Column]:
    return [
        Column(f"{prefix}_{g}", f"{header} {g}", METRICS[metric].better)
        for prefix, _, metric, header in columns
        for g in GROUP_ORDER
    ]


def _t32_pivot(t32: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """Table 3.2's ``(method, lighting)`` rows as one row per method, ``<metric>_<lighting>``."""
    out: dict[str, dict[str, Any]] = {}
    for r in t32:
        row = out.setdefault(r["method"], {"method": r["method"]})
        row.update({f"{k}_{r['lighting']}": r[k] for k, _, _ in TABLE_3_2_COLUMNS})
    return list(out.values())


def _t32_columns(keys: Sequence[str]) -> list[Column]:
    label = {"mse": "si-MSE"}
    return [
        Column(f"{key}_{g}", f"{label.get(key, header)} {g}", METRICS[metric].better)
        for key, metric, header in TABLE_3_2_COLUMNS
        if key in keys
        for g in (*GROUP_ORDER, "all")
    ]


def _kind_tables(label: str, rows: Sequence[Mapping[str, Any]], columns: list[Column]) -> list[str]:
    md = []
    for kind, name in SCENE_KINDS.items():
        sel = [r for r in rows if r["scene_kind"] == kind]
        if sel:
            md += [f"### {label}: {name}", "", markdown_table(sel, columns), ""]
    return md or ["No samples scored.", ""]


def _titled(title: str, note: str) -> list[str]:
    """A markdown title and, when there is one, the evaluation target's note below it."""
    return [f"# {title}", "", note, ""] if note else [f"# {title}", ""]


def _intro(
    methods: Mapping[str, Any],
    inputs: Sequence[str],
    samples: Mapping[str, tuple[str, str]],
    note: str,
) -> list[str]:
    kinds = [k for k, _ in samples.values()]
    return [
        *_titled("Evaluation report", note),
        f"{len(samples)} samples ({kinds.count('object')} single objects, "
        f"{kinds.count('complex')} complex-scene views); input decomposed: "
        + ", ".join(f"`{k}`" for k in inputs)
        + f" (the first of {list(INPUT_LAYERS)} each "
        f"sample has); methods: {', '.join(methods)}. Every number is a mean over samples on "
        "the sRGB input; the CSV files beside this report hold the same rows to 6 significant "
        "digits.",
        "",
    ]


def _report_md(
    methods: Mapping[str, Any],
    inputs: Sequence[str],
    samples: Mapping[str, tuple[str, str]],
    tables: Mapping[str, list[dict[str, Any]]],
    files: Mapping[str, Path],
    note: str = "",
) -> str:
    summary = tables["summary"]
    conds = [k for k in (summary[0] if summary else {}) if k != "method"]
    md = _intro(methods, inputs, samples, note)
    md += ["## Summary: reflectance LMSE by method and lighting condition", ""]
    md += (
        [
            markdown_table(
                summary, [Column("method", "method"), *(Column(c, c, "lower") for c in conds)]
            ),
            "",
            f"![Reflectance LMSE, method x lighting condition]({SUMMARY_FIGURE})",
            "",
        ]
        if summary
        else ["No reflectance LMSE scored (see `--metrics`).", ""]
    )
    md += glossary_section()
    md += ["## LMSE by lighting group (like thesis Tables 5.3 and 5.4)", ""]
    md += _kind_tables(
        "LMSE", tables["lmse"], [Column("method", "method"), *_group_columns(LMSE_COLUMNS)]
    )
    md += ["## Coloured-shading metrics by lighting group", ""]
    md += _kind_tables(
        "Coloured shading",
        tables["colour"],
        [Column("method", "method"), *_group_columns(COLOUR_COLUMNS)],
    )
    pivot = _t32_pivot(tables["t32"])
    note = (
        "Single objects; mean over samples of (grey shading + grey reflectance) / 2, grey = "
        "mean over channels, as thesis sec. 3.5."
    )
    for title, keys in (
        ("scale-invariant global metrics (Corr., si-MSE)", ("corr", "mse")),
        ("local metrics (LMSE, aLMSE)", ("lmse", "almse")),
    ):
        md += [f"## Like thesis Table 3.2: {title}", "", note, ""]
        md += [
            markdown_table(pivot, [Column("method", "method"), *_t32_columns(keys)])
            if pivot
            else "No single-object samples scored.",
            "",
        ]
    md += _scenario_md(tables["scenario"])
    md += sensor_md(tables["sensor"])
    md += _methods_md(methods)
    md += ["## Files", ""] + [f"* `{p.name}`" for p in files.values()]
    md += [f"* `{SUMMARY_FIGURE}`"] if summary else []
    return "\n".join(md) + "\n"


def _scenario_md(rows: Sequence[Mapping[str, Any]]) -> list[str]:
    md = ["## Reflectance LMSE by photometric scenario (like thesis Table 5.1)", ""]
    if not rows:
        return md + ["No camera renderings scored: Table 5.1 needs `image_camera/<name>`.", ""]
    cols = [Column("method", "method"), *(Column(sc, sc, "lower") for sc in _PHOTOMETRIC)]
    for camera in sorted({r["camera"] for r in rows}):
        md += [
            f"### Camera {camera}",
            "",
            markdown_table([r for r in rows if r["camera"] == camera], cols),
            "",
        ]
    return md


def _methods_md(methods: Mapping[str, Any]) -> list[str]:
    md = ["## Methods and parameters", ""]
    for name, record in method_parameters(methods).items():
        params = ", ".join(f"{k}={v!r}" for k, v in record["parameters"].items() if k != "name")
        md.append(f"* **{name}** (`{record['class']}`): {params or 'no parameters'}")
        protocol = getattr(methods[name], "protocol", "")
        if protocol:
            md.append(f"  * parameters chosen by: {protocol}")
    return md + [""]


def _scenario_files(out: Path, rows: list[dict[str, Any]], note: str) -> dict[str, Path]:
    cols = ["camera", "method", *_PHOTOMETRIC]
    _write_csv(out / "lmse_by_scenario.csv", rows, cols)
    md = _titled("Reflectance LMSE by photometric scenario (like thesis Table 5.1)", note)
    md += [
        _markdown(rows, cols, cols)
        if rows
        else "No camera renderings scored: Table 5.1 needs `image_camera/<name>`."
    ]
    write_text_file(out / "lmse_by_scenario.md", "\n".join(md) + "\n")
    return {
        "scenario_csv": out / "lmse_by_scenario.csv",
        "scenario_md": out / "lmse_by_scenario.md",
    }


def _t32_files(out: Path, t32: list[dict[str, Any]], note: str) -> dict[str, Path]:
    cols = ["method", "lighting", *(k for k, _, _ in TABLE_3_2_COLUMNS)]
    _write_csv(out / "table_3_2_objects.csv", t32, cols)
    md = [
        *_titled("Single objects, like thesis Table 3.2 (MIT-20)", note),
        "Mean over samples of (grey shading + grey reflectance) / 2, grey = mean over "
        "channels, as the thesis (sec. 3.5); MSE is the scale-invariant MSE (Eq. 2.4).",
        "",
        _markdown(t32, cols, ["method", "light", *(h for _, _, h in TABLE_3_2_COLUMNS)])
        if t32
        else "No single-object samples scored.",
    ]
    write_text_file(out / "table_3_2_objects.md", "\n".join(md) + "\n")
    return {
        "table_3_2_csv": out / "table_3_2_objects.csv",
        "table_3_2_md": out / "table_3_2_objects.md",
    }


def _summary_files(out: Path, summary: list[dict[str, Any]]) -> dict[str, Path]:
    if not summary:
        return {}
    conds = [k for k in summary[0] if k != "method"]
    _write_csv(out / "summary_by_condition.csv", summary, ["method", *conds])
    summary_heatmap(
        out / SUMMARY_FIGURE,
        summary,
        conds,
        title="Reflectance LMSE (lower is better), mean over samples",
    )
    return {"summary_csv": out / "summary_by_condition.csv"}


def write_report(out: Path, run: EvaluationResult) -> dict[str, Path]:
    """Write ``scores.csv``, the summary, condition and scenario tables, ``methods.json``, the
    summary figure (:data:`~spectrinsic.decompose.report.figure.SUMMARY_FIGURE`) and
    ``REPORT.md``, which holds every table's numbers inline
    (:mod:`spectrinsic.decompose.report.markdown`). ``run.note``
    (:func:`spectrinsic.decompose.evaluation.targets.target_note`) is printed under every title.
    Each ``scores.csv`` row names its sample's lighting group (WL/1L/2L, measured from its
    lights: the condition in ``run.samples``) and, where ``run.config_hashes`` gives it, the sample's dataset
    config hash. *run* is :func:`~spectrinsic.decompose.evaluation.evaluate.evaluate`'s record."""
    scores, samples, methods, note = run.scores, run.samples, run.methods, run.note
    files: dict[str, Path] = {"scores": out / "scores.csv"}
    hashes = run.config_hashes
    _write_csv(
        files["scores"],
        [
            {
                "sample": s.sample,
                "method": s.method,
                "scenario": s.scenario,
                "layer": s.layer,
                "metric": s.metric,
                "value": s.value,
                "lighting": condition_group(samples[s.sample][1]) if s.sample in samples else "",
                "config_hash": hashes.get(s.sample, ""),
            }
            for s in scores
        ],
        ("sample", "method", "scenario", "layer", "metric", "value", "lighting", "config_hash"),
    )
    tables = {
        "summary": summary_table(scores, samples),
        "lmse": condition_table(scores, samples, columns=LMSE_COLUMNS),
        "colour": condition_table(scores, samples, columns=COLOUR_COLUMNS),
        "scenario": scenario_table(scores),
        "sensor": sensor_table(scores),
        "t32": table_3_2(scores, samples),
    }
    files.update(_summary_files(out, tables["summary"]))
    files.update(
        _condition_files(
            out,
            "lmse_by_condition",
            "LMSE by lighting condition (like thesis Tables 5.3 and 5.4)",
            tables["lmse"],
            LMSE_COLUMNS,
            note,
        )
    )
    files.update(
        _condition_files(
            out,
            "colour_by_condition",
            "Coloured-shading metrics by lighting condition",
            tables["colour"],
            COLOUR_COLUMNS,
            note,
        )
    )
    files.update(_scenario_files(out, tables["scenario"], note))
    files.update(_t32_files(out, tables["t32"], note))
    files["methods"] = out / "methods.json"
    write_json(files["methods"], method_parameters(methods), strict=False, default=str, end="")
    files["report"] = out / "REPORT.md"
    write_text_file(files["report"], _report_md(methods, run.inputs, samples, tables, files, note))
    return files
