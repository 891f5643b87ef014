"""Issue 19: REPORT.md holds the numbers. Scores made here (two methods on four object samples,
one per condition, and one complex view) go through write_report; the report is parsed back and
its tables checked against means computed here and against the CSV files beside it."""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.decompose.evaluation.evaluate import EvaluationResult
from spectrinsic.decompose.evaluation.scores import Score
from spectrinsic.decompose.report import write_report
from spectrinsic.decompose.report.markdown import GLOSSARY

CONDITIONS = ("white", "one-colour", "two-colour-a", "two-colour-b")
SAMPLES = {f"obj-a__v0__{c}": ("object", c) for c in CONDITIONS} | {
    "room-x__v0__white": ("complex", "white")
}
#: Printed numbers have 4 significant digits.
PRINTED = 5e-4


@dataclass(frozen=True)
class Flat:
    level: float = 0.5


@dataclass(frozen=True)
class Noisy:
    sigma: float = 2.0


def _scores() -> list[Score]:
    rng = np.random.default_rng(7)
    out = []
    for sid in SAMPLES:
        for method, scale in (("flat", 1.0), ("noisy", 3.0)):
            for layer in ("reflectance", "shading", "shading_grey", "reflectance_grey"):
                for metric in ("lmse", "si_mse", "almse", "corr"):
                    value = (
                        float(rng.uniform(0.01, 0.1) * scale)
                        if metric != "si_mse"
                        else float(rng.uniform(100, 500))
                    )
                    out.append(Score(sid, method, "srgb", layer, metric, value))
            out.append(
                Score(
                    sid, method, "srgb", "shading", "shading_chromaticity", float(rng.uniform(1, 9))
                )
            )
    return out


def _tables(md: str) -> dict[str, tuple[list[str], list[list[str]]]]:
    """``{heading: (header cells, rows of cells)}`` of every Markdown table, by the nearest
    heading above it."""
    out, heading, block = {}, "", []
    for line in [*md.splitlines(), ""]:
        if line.startswith("#"):
            heading = line.lstrip("#").strip()
        if line.startswith("|"):
            block.append([c.strip() for c in line.strip("|").split("|")])
        elif block:
            out[heading] = (block[0], block[2:])
            block = []
    return out


def _number(cell: str) -> float:
    return float("nan") if cell.strip("*") == "—" else float(cell.strip("*"))


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> tuple[Path, str, list[Score]]:
    out = tmp_path_factory.mktemp("report")
    scores = _scores()
    methods = {"flat": Flat(), "noisy": Noisy()}
    write_report(out, EvaluationResult(tuple(scores), SAMPLES, methods, ("image_denoised",)))
    return out, (out / "REPORT.md").read_text(encoding="utf-8"), scores


def test_first_table_is_reflectance_lmse_per_method_and_condition(report):
    out, md, scores = report
    first = next(iter(_tables(md).items()))
    assert first[0].startswith("Summary: reflectance LMSE")
    header, rows = first[1]
    assert header == ["method", *(f"{c} ↓" for c in CONDITIONS), "all ↓"]
    csv_rows = {r["method"]: r for r in csv.DictReader((out / "summary_by_condition.csv").open())}
    for row in rows:
        method = row[0]
        for cond, cell in zip([*CONDITIONS, "all"], row[1:], strict=True):
            want = np.mean(
                [
                    s.value
                    for s in scores
                    if s.method == method
                    and s.layer == "reflectance"
                    and s.metric == "lmse"
                    and (cond == "all" or SAMPLES[s.sample][1] == cond)
                ]
            )
            assert _number(cell) == pytest.approx(want, rel=PRINTED), (method, cond)
            assert float(csv_rows[method][cond]) == pytest.approx(want, rel=1e-5)


def test_best_of_every_column_is_bold_and_arrows_say_which_way(report):
    _, md, _ = report
    for heading, (header, rows) in _tables(md).items():
        if heading == "Abbreviations" or len(rows) < 2:
            continue
        for j, title in enumerate(header[1:], start=1):
            assert title.endswith(("↓", "↑")), (heading, title)
            values = [_number(r[j]) for r in rows]
            if np.isnan(values).all():
                assert not any(r[j].startswith("**") for r in rows)
                continue
            best = np.nanmin(values) if title.endswith("↓") else np.nanmax(values)
            bold = [_number(r[j]) for r in rows if r[j].startswith("**")]
            assert bold and all(b == best for b in bold), (heading, title)


def test_lmse_table_matches_its_csv_and_si_mse_is_kept_apart(report):
    out, md, _ = report
    tables = _tables(md)
    header, rows = tables["LMSE: single objects"]
    csv_rows = [
        r
        for r in csv.DictReader((out / "lmse_by_condition.csv").open())
        if r["scene_kind"] == "object"
    ]
    assert [r[0] for r in rows] == [r["method"] for r in csv_rows]
    assert header[1] == "refl. WL ↓"
    for row, want in zip(rows, csv_rows, strict=True):
        assert _number(row[1]) == pytest.approx(float(want["reflectance_WL"]), rel=PRINTED)
        assert _number(row[6]) == pytest.approx(float(want["shading_grey_2L"]), rel=PRINTED)
    for heading, (header, _) in tables.items():
        text = " ".join(header)
        assert not ("si-MSE" in text and "LMSE" in text), heading  # never side by side
    si = tables["Like thesis Table 3.2: scale-invariant global metrics (Corr., si-MSE)"]
    assert "si-MSE all ↓" in si[0] and "Corr. all ↑" in si[0]


def test_every_abbreviation_is_defined_once_and_the_figure_is_embedded(report):
    out, md, _ = report
    header, rows = _tables(md)["Abbreviations"]
    terms = [r[0] for r in rows]
    assert terms == [t for t, _ in GLOSSARY] and len(set(terms)) == len(terms)
    assert md.count("## Abbreviations") == 1
    for word in ("WL", "1L", "2L", "LMSE", "aLMSE", "si-MSE", "Corr.", "SC1", "SC3b", "SC4"):
        assert word in terms
    used = {
        w
        for h, _ in _tables(md).values()
        for cell in h
        for w in re.findall(r"\b(?:WL|1L|2L|SC\w+)\b", cell)
    }
    assert used <= set(terms)
    assert "![Reflectance LMSE, method x lighting condition](summary.png)" in md
    assert (out / "summary.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
