"""Issue 19, tried as a new user would: preview build -> check exits 0 -> load -> batches ->
evaluate with predictions written by the helper -> the report holds the numbers."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from spectrinsic.cli import main

pytestmark = pytest.mark.slow


def test_preview_build_checks_loads_batches_and_scores(tmp_path, capsys):
    from spectrinsic.decompose import write_predictions
    from spectrinsic.gt_export import load_dataset
    from spectrinsic.gt_export.collate import collate_arrays
    from spectrinsic.gt_export.loader import prepare_item

    data = tmp_path / "preview"
    assert (
        main(
            [
                "-q",
                "dataset",
                "--preset",
                "preview",
                "--only",
                "obj-apple*",
                "--out",
                str(data),
                "--workers",
                "1",
            ]
        )
        == 0
    )
    capsys.readouterr()
    assert main(["-q", "check", str(data)]) == 0  # the preview's noise is a warning, not a failure
    assert "ok: 4 samples" in capsys.readouterr().out

    samples = list(load_dataset(data))
    batch = collate_arrays([prepare_item(s) for s in samples])
    assert batch["image"].shape == (4, 3, 48, 48)
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
                str(data),
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
        m: [
            float(r["value"])
            for r in rows
            if r["method"] == m and r["metric"] == "lmse" and r["layer"] == "reflectance"
        ]
        for m in ("truth", "image-as-reflectance")
    }
    assert len(lmse["truth"]) == 4 and max(lmse["truth"]) < 1e-6
    assert np.mean(lmse["image-as-reflectance"]) > 100 * max(max(lmse["truth"]), 1e-9)
    assert (out / "REPORT.md").is_file()
