"""Issue 19: splits that exist. Three tiny scenes built from the command line: every split holds
one, the fractions are an option (not hashed: a resume rewrites only the manifest), and an
empty split is an error naming the split and the scene count."""

from __future__ import annotations

import json

import pytest

from spectrinsic.cli import main
from spectrinsic.errors import DatasetError
from spectrinsic.gt_export.dataset.loader import split_samples

THREE = "obj-apple__v0__white,obj-cup__v0__white,obj-deer__v0__white"
TINY = ["--preset", "preview", "--resolution", "12x12", "--spp", "2", "--workers", "1"]


def test_three_scenes_fill_every_split_and_the_fractions_are_an_option(tmp_path, capsys):
    out = tmp_path / "three"
    assert main(["-q", "dataset", *TINY, "--only", THREE, "--out", str(out)]) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["split_fractions"] == {"train": 0.8, "val": 0.1, "test": 0.1}
    assert sorted(len(v) for v in manifest["splits"].values()) == [1, 1, 1]
    for split in ("train", "val", "test"):
        assert len(split_samples(out, split)) == 1
    assert "train 1 samples (1 scenes)" in (out / "DATASET.md").read_text()

    capsys.readouterr()
    assert (
        main(
            [
                "dataset",
                *TINY,
                "--only",
                THREE,
                "--out",
                str(out),
                "--split-fractions",
                "0.34,0.33,0.33",
            ]
        )
        == 0
    )
    assert "built 0, skipped 3" in capsys.readouterr().out  # the fractions are not hashed
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["split_fractions"] == {"train": 0.34, "val": 0.33, "test": 0.33}


def test_an_empty_split_names_the_split_and_the_scene_count(tmp_path):
    out = tmp_path / "one"
    assert main(["-q", "dataset", *TINY, "--only", "obj-apple__v0__white", "--out", str(out)]) == 0
    assert len(split_samples(out, "train")) == 1
    with pytest.raises(
        DatasetError, match=r"split 'val' .* is empty: the dataset has 1 scene\(s\) for 3 splits"
    ):
        split_samples(out, "val")


@pytest.mark.parametrize("text", ["0.8,0.2", "0.8,0.1,x", "0.9,0.1,0", "0.5,0.2,0.2"])
def test_bad_split_fractions_are_refused_before_any_work(tmp_path, capsys, text):
    out = tmp_path / "never"
    assert (
        main(
            [
                "dataset",
                *TINY,
                "--only",
                "obj-apple__v0__white",
                "--out",
                str(out),
                "--split-fractions",
                text,
            ]
        )
        == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and ("--split-fractions" in err[0] or "split fractions" in err[0]), err
    assert not out.exists()
