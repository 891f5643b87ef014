"""Issue 19: study output defines its abbreviations and sets each number that has a thesis value
beside it with the difference and, where known, its cause."""

from __future__ import annotations

import re

import pytest

from spectrinsic.studies.glossary import STUDY_TERMS
from spectrinsic.studies.photometric import PhotometricSettings, format_photometric, run_photometric
from spectrinsic.studies.photometric.report import GAP_CAUSES
from spectrinsic.studies.reconstruction import THESIS_TABLE_5_2, format_table, reconstruction_table
from spectrinsic.studies.rendering.compute import THESIS_MEAN_R
from spectrinsic.studies.rendering.report import R_GAP_CAUSE, format_rendering


def _defined(text: str) -> dict[str, str]:
    """The abbreviations block of a study's text: ``{term: meaning}``."""
    block = text.split("Abbreviations:\n", 1)[1].splitlines()
    return dict(line.strip().split(None, 1) for line in block if line.startswith("  "))


def test_reconstruction_table_prints_each_difference_from_table_5_2():
    table = reconstruction_table()
    text = format_table(table)
    cells = re.findall(r"(\d+\.\d\d) \[\s*(\d+\.\d\d) ([+-]\d+\.\d\d)\]", text)
    assert len(cells) == 3 * len(THESIS_TABLE_5_2)
    for ours, thesis, diff in cells:
        assert float(diff) == pytest.approx(float(ours) - float(thesis), abs=0.011)
    assert re.search(r"1[0-9] of 18 thesis numbers reproduced to two decimals", text)
    assert _defined(text) == {k: STUDY_TERMS[k] for k in ("ε", "s.d.")}


def test_photometric_changes_carry_their_gap_and_its_cause(monkeypatch):
    monkeypatch.delenv("SPECTRINSIC_DATA", raising=False)
    result = run_photometric(PhotometricSettings(seed=5, n_scenes=3, reflectances_per_scene=60))
    text = format_photometric(result)
    for key, cause in GAP_CAUSES.items():
        (line,) = [ln for ln in text.splitlines() if ln.startswith(key)]
        ours, table = result.changes["ours"][key], result.changes["thesis_table_4_4"][key]
        assert f"{round(ours - table, 1) + 0.0:+.1f} vs thesis {table:.1f} ({cause})" in line
    assert "+48 %" in GAP_CAUSES["SC2_vs_SC1"] and "+72 %" in GAP_CAUSES["SC2_vs_SC1"]
    assert set(_defined(text)) == {"SC1", "SC2", "SC3", "SC4", "A_vs_B"}


def test_rendering_summary_sets_r_beside_the_thesis_and_defines_e3_e6_r():
    row = {
        "scene": "room-x",
        "view": 0,
        "condition": "two-colour-a",
        "err3_mean_pct": 1.0,
        "err3_max_pct": 2.0,
        "err3g_mean_pct": 0.9,
        "err6_mean_pct": 0.5,
        "err6_max_pct": 1.0,
        "energy_ratio_r": 0.7,
    }
    summary = {
        "n_rows": 1,
        "err3_mean_pct": 1.0,
        "err3g_mean_pct": 0.9,
        "err6_mean_pct": 0.5,
        "energy_ratio_r_mean": 0.7,
    }
    text = format_rendering({"rows": [row], "summary": summary})
    assert (
        f"r 0.700 ({0.7 - THESIS_MEAN_R:+.2f} vs thesis {THESIS_MEAN_R:.2f} ({R_GAP_CAUSE}))"
        in text
    )
    header = text.splitlines()[0].split()
    used = {w for w in header if w in STUDY_TERMS}
    assert used == {"v", "e3", "e3g", "e6", "r"} and used <= set(_defined(text))
