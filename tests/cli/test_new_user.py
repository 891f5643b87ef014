"""Issue 19, tried as a new user would: preview build -> check exits 0 -> load -> batches of 8
(a torch DataLoader where torch is installed: ``make test-torch``, which CI runs) -> evaluate
with predictions written by the helper -> REPORT.md holds the numbers."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from spectrinsic.cli import main

pytestmark = pytest.mark.slow

#: Two objects under the four conditions: 8 samples, one batch of 8.
ONLY = "obj-apple*,obj-cup*"
#: REPORT.md prints four significant digits.
PRINTED = 5e-4


@pytest.fixture(scope="module")
def preview(tmp_path_factory):
    """The README's first build, on two of its objects."""
    data = tmp_path_factory.mktemp("new-user") / "preview"
    assert (
        main(
            [
                "-q",
                "dataset",
                "--preset",
                "preview",
                "--only",
                ONLY,
                "--out",
                str(data),
                "--workers",
                "1",
            ]
        )
        == 0
    )
    return data


def _first_table(md: str) -> tuple[list[str], dict[str, list[str]]]:
    """Header and ``{method: cells}`` of REPORT.md's first table."""
    rows = [
        [c.strip() for c in line.strip().strip("|").split("|")]
        for line in md.split("\n\n| ", 1)[1].split("\n\n", 1)[0].splitlines()
    ]
    rows[0][0] = rows[0][0].lstrip("| ")
    return rows[0], {r[0]: r[1:] for r in rows[2:]}


def test_preview_build_checks_loads_batches_and_scores(preview, tmp_path, capsys):
    from spectrinsic.decompose import write_predictions
    from spectrinsic.gt_export import load_dataset
    from spectrinsic.gt_export.dataset.collate import collate_arrays
    from spectrinsic.gt_export.dataset.loader import prepare_item

    capsys.readouterr()
    assert (
        main(["-q", "check", str(preview)]) == 0
    )  # the preview's noise is a warning, not a failure
    assert "ok: 8 samples" in capsys.readouterr().out

    # the sRGB view: what evaluate scores against (README, "Decompose each sample's ...")
    samples = list(load_dataset(preview, space="srgb"))
    batch = collate_arrays([prepare_item(s) for s in samples])  # what collate does without torch
    assert batch["image"].shape == (8, 3, 48, 48)
    assert batch["light_mask"].sum(axis=1).tolist() == [len(s["meta"]["lights"]) for s in samples]
    assert max(len(s["meta"]["lights"]) for s in samples) == 2  # the two-colour conditions

    for s in samples:  # a perfect method: the ground truth itself, as 16-bit PNG
        write_predictions(
            tmp_path / "truth",
            s["meta"]["sample_id"],
            fmt="png",
            reflectance=s["reflectance"],
            shading=s["shading"],
        )
    out = tmp_path / "scores"
    assert (
        main(
            [
                "-q",
                "evaluate",
                "--dataset",
                str(preview),
                "--predictions",
                f"truth={tmp_path / 'truth'}",
                "--methods",
                "image-as-reflectance",
                "--out",
                str(out),
                "--no-figures",
                "--no-cameras",
            ]
        )
        == 0
    )
    rows = list(csv.DictReader((out / "scores.csv").open()))
    lmse = {
        m: {
            r["sample"]: float(r["value"])
            for r in rows
            if r["method"] == m
            and r["metric"] == "lmse"
            and r["layer"] == "reflectance"
            and r["scenario"] == "srgb"
        }
        for m in ("truth", "image-as-reflectance")
    }
    assert len(lmse["truth"]) == 8 and max(lmse["truth"].values()) < 1e-6
    assert np.mean(list(lmse["image-as-reflectance"].values())) > 100 * max(
        max(lmse["truth"].values()), 1e-9
    )

    md = (out / "REPORT.md").read_text(encoding="utf-8")  # the numbers, not file names
    header, table = _first_table(md)
    assert (
        header[0] == "method"
        and header[-1] == "all ↓"
        and set(table) == {"truth", "image-as-reflectance"}
    )
    for method, cells in table.items():
        for condition, cell in zip([h.removesuffix(" ↓") for h in header[1:]], cells, strict=True):
            values = [
                v
                for sid, v in lmse[method].items()
                if condition == "all" or sid.endswith(f"__{condition}")
            ]
            assert float(cell.strip("*")) == pytest.approx(
                np.mean(values), rel=PRINTED, abs=1e-9
            ), (method, condition)
    assert all(c.startswith("**") for c in table["truth"])  # the best of every column
    assert "![Reflectance LMSE, method x lighting condition](summary.png)" in md
    assert (out / "summary.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.torch
def test_the_preview_build_feeds_a_dataloader_in_batches_of_8(preview, torch):
    from spectrinsic.gt_export import torch_dataset
    from spectrinsic.gt_export.dataset.collate import collate

    loader = torch.utils.data.DataLoader(torch_dataset(preview), batch_size=8, collate_fn=collate)
    (batch,) = list(loader)
    assert batch["image"].shape == (8, 3, 48, 48) and batch["image"].dtype == torch.float32
    assert batch["light_share"].shape == (8, 2, 48, 48)
    assert sorted(batch["light_mask"].sum(dim=1).tolist()) == [1, 1, 1, 1, 2, 2, 2, 2]
