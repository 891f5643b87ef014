"""A dataset rerun never writes through a link: the gallery, the card and the contact sheet
are renamed over their names (:mod:`spectrinsic.file_writes`), and a link planted while the
build runs is refused when the file is written, not only at the start."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from spectrinsic.errors import WriteError
from tests.conftest import USER_TEXT


def test_a_rerun_of_the_gallery_and_card_leaves_hard_linked_files_alone(
    tmp_path, outside, one_light_sample, config
):
    from spectrinsic.gt_export import build_gallery, export_sample
    from spectrinsic.gt_export.dataset.card import write_dataset_card

    root = tmp_path / "ds"
    export_sample(
        root, one_light_sample[0], one_light_sample[1], sample_id="s", config=config, seed=1
    )
    build_gallery(root)
    write_dataset_card(root, config=config)
    names = ("gallery.json", "index.html", "DATASET.md", "contact_sheet.png")
    for name in names:
        (root / name).unlink()
        os.link(outside, root / name)
    build_gallery(root)
    write_dataset_card(root, config=config)
    assert outside.read_text() == USER_TEXT
    assert all((root / n).stat().st_ino != outside.stat().st_ino for n in names)


def test_a_link_planted_while_the_gallery_is_built_is_not_written_through(
    tmp_path, outside, one_light_sample, config, monkeypatch
):
    from spectrinsic.gt_export import build_gallery, export_sample
    from spectrinsic.gt_export.dataset import gallery

    root = tmp_path / "ds"
    export_sample(
        root, one_light_sample[0], one_light_sample[1], sample_id="s", config=config, seed=1
    )
    real = gallery.contact_sheet

    def sheet_then_plant(folder: Path, **options: object) -> Path:
        made = real(folder, **options)
        if not (root / "index.html").is_symlink():
            (root / "index.html").symlink_to(outside)  # planted after the run's start checks
        return made

    monkeypatch.setattr(gallery, "contact_sheet", sheet_then_plant)
    with pytest.raises(WriteError, match=r"index\.html.*symbolic link"):
        build_gallery(root)
    assert outside.read_text() == USER_TEXT
