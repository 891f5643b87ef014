"""How to cite, licence and intended use (issue 31): CITATION.cff names the project and the
thesis; the dataset card has licence, citation and intended-use sections."""

from __future__ import annotations

from pathlib import Path

import yaml

from spectrinsic.gt_export.dataset.card import read_template

ROOT = Path(__file__).resolve().parents[1]


def test_citation_file_names_the_software_and_the_thesis():
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["cff-version"] == "1.2.0" and cff["type"] == "software"
    assert cff["license"] == "GPL-3.0-or-later"
    thesis = cff["preferred-citation"]
    assert thesis["type"] == "thesis" and "intrinsic images" in thesis["title"]
    assert thesis["authors"][0]["family-names"] == "Serra"


def test_the_dataset_card_has_licence_citation_and_intended_use():
    card = read_template("DATASET.md")
    for section in ("## Intended use", "## Licence", "## Citation"):
        assert section in card
    assert "GPL-3.0-or-later" in card and "CITATION.cff" in card
