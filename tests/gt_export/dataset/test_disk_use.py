"""The card's sizes are the folder's own bytes (issue 45): measured from the sample folders,
checked here against an independent walk of the folder, with the per-10,000 projection
10,000 × the mean and samples of different kinds summarised apart."""

from __future__ import annotations

import os
from pathlib import Path

from spectrinsic.gt_export.dataset.card_sizes import byte_size, size_section
from spectrinsic.gt_export.dataset.disk_use import disk_use, sample_kind
from spectrinsic.gt_export.sample import sample_dirs


def _walked(folder: Path) -> tuple[int, int]:
    """``(bytes outside previews/, bytes inside)`` of *folder*, by ``os.walk``."""
    data = previews = 0
    for here, _, files in os.walk(folder):
        size = sum(os.path.getsize(os.path.join(here, f)) for f in files)
        if os.path.relpath(here, folder).split(os.sep)[0] == "previews":
            previews += size
        else:
            data += size
    return data, previews


def _card_row(card: str, label: str) -> list[str]:
    row = next(line for line in card.splitlines() if line.startswith(f"| {label} |"))
    return [cell.strip() for cell in row.strip("|").split("|")]


def test_the_cards_sizes_are_the_folders_bytes(built):
    walked = {p.name: _walked(p) for p in sorted(built.iterdir()) if (p / "meta.json").is_file()}
    assert len(walked) == 2 and all(d > 0 and v > 0 for d, v in walked.values())
    use = disk_use(sample_dirs(built))
    assert {s.sample_id: (s.data, s.previews) for s in use.samples} == walked
    data = [d for d, _ in walked.values()]
    assert use.total == sum(d + v for d, v in walked.values())
    assert (use.data.smallest, use.data.largest, use.data.total) == (
        min(data),
        max(data),
        sum(data),
    )
    assert use.data.projected == 10_000 * sum(data) / len(data)  # a projection: 10,000 × mean

    card = (built / "DATASET.md").read_text(encoding="utf-8")
    assert f"its 2 sample folders hold **{byte_size(use.total)}**" in card
    mean = sum(data) / len(data)
    row = _card_row(card, "all, without previews")
    assert row == [
        "all, without previews",
        "2",
        byte_size(mean),
        byte_size(min(data)),
        byte_size(max(data)),
        byte_size(sum(data)),
        byte_size(10_000 * mean),
    ]
    previews = [v for _, v in walked.values()]
    assert _card_row(card, "previews only (`previews/`, PNG)")[-1] == byte_size(
        10_000 * sum(previews) / 2
    )
    assert "with transport" not in card  # one kind: no rows per kind
    assert "Build time: not recorded" in card  # written outside a build: no time claimed


def test_samples_with_a_transport_are_summarised_apart(tmp_path):
    sizes = {"plain-a": 1_000, "plain-b": 3_000, "relit-a": 50_000}
    for name, size in sizes.items():
        folder = tmp_path / name
        (folder / "previews").mkdir(parents=True)
        (folder / "meta.json").write_bytes(b"{}")
        big = "transport.exr" if name.startswith("relit") else "image.exr"
        (folder / big).write_bytes(b"\0" * size)
        (folder / "previews" / "image.png").write_bytes(b"\0" * 7)
    use = disk_use(sorted(tmp_path.iterdir()))
    assert [sample_kind(tmp_path / n) for n in sizes] == ["plain", "plain", "transport"]
    kinds = use.by_kind
    assert (kinds["plain"].samples, kinds["plain"].mean) == (2, 2_002)
    assert (kinds["transport"].smallest, kinds["transport"].largest) == (50_002, 50_002)
    assert use.previews.total == 21
    text = size_section(use, None, ["scalar_spectral"])
    assert _card_row(text, "with transport")[1:3] == ["1", byte_size(50_002)]
    assert _card_row(text, "plain")[-1] == byte_size(20_020_000)


def test_a_linked_file_is_not_counted(tmp_path):
    folder = tmp_path / "s"
    folder.mkdir()
    (folder / "meta.json").write_bytes(b"{}")
    (tmp_path / "elsewhere.bin").write_bytes(b"\0" * 5_000)
    (folder / "link.bin").symlink_to(tmp_path / "elsewhere.bin")
    assert disk_use([folder]).samples[0].data == 2


def test_byte_sizes_round_into_the_next_unit():
    sizes = (999.4, 999.6, 999_400_000, 999_600_000, 1e18, 2e21)
    assert [byte_size(n) for n in sizes] == [
        "999 B",
        "1.00 kB",
        "999 MB",
        "1.00 GB",
        "1.00 EB",
        "2000 EB",
    ]
