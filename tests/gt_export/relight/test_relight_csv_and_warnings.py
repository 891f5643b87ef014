"""``relight`` verifies the CSV spectra it reads again against ``meta.json["spectrum_files"]``,
and prints exactly one line (no arithmetic warnings before it).

A sample whose material is a column of a CSV file was relit after an edit to that CSV with
rc 0, and every layer holding the reflectance changed. Now the file's SHA-256 is checked
against the one recorded at build time, and a mismatch is refused in one line naming the file.
"""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import spectrinsic
from spectrinsic.cli import main
from spectrinsic.gt_export.layers import LayerSettings
from spectrinsic.gt_export.sample.meta import read_meta
from spectrinsic.render import RenderSettings
from tests.gt_export._builders import render_transport_sample

SETTINGS = RenderSettings(spp=1, modes=("rgb3",), batches=1, max_depth=2)
CSV = "wavelength [nm],paint [%]\n380,40\n550,60\n780,20\n"


@pytest.fixture(scope="module")
def source(tmp_path_factory, make_room) -> tuple[Path, Path]:
    """An 8x8 room sample whose first material is a CSV column, stored with its transport."""
    out = tmp_path_factory.mktemp("relight-csv")
    csv = out / "paints.csv"
    csv.write_text(CSV)
    room = make_room(size=8)
    first = dataclasses.replace(room.materials[0], spectrum=f"csv:{csv}#paint [%]")
    scene = dataclasses.replace(room, materials=(first, *room.materials[1:]))
    sample, _, _ = render_transport_sample(
        out / "ds", scene, SETTINGS, seed=3, sample_id="s", config={"t": 44},
        layers=LayerSettings().for_scene_folder(out),
    )  # fmt: skip
    return sample, csv


def _relight(sample: Path, out: Path, capsys, *options: str) -> tuple[int, str]:
    scene_dir = ["--scene-dir", str(sample.parent.parent)]  # where paints.csv lies
    rc = main(["relight", str(sample), "--light", "0=planck:3000K", "--out", str(out), *scene_dir])
    return rc, capsys.readouterr().err.strip()


def test_the_csv_a_sample_read_is_recorded_with_its_sha256(source):
    sample, csv = source
    files = read_meta(sample).raw["spectrum_files"]
    assert [f["column"] for f in files] == ["paint [%]"]
    assert files[0]["file"] == "paints.csv"  # relative to the scene's folder
    import hashlib

    assert files[0]["sha256"] == hashlib.sha256(csv.read_bytes()).hexdigest()


def test_an_edited_spectrum_csv_is_refused_by_relight_naming_the_file(source, tmp_path, capsys):
    sample, csv = source
    rc, err = _relight(sample, tmp_path / "before", capsys)
    assert rc == 0, err  # the unedited CSV relights
    try:
        csv.write_text(CSV.replace("550,60", "550,61"))  # still a valid spectrum
        rc, err = _relight(sample, tmp_path / "after", capsys)
    finally:
        csv.write_text(CSV)
    assert rc == 2 and "\n" not in err, err
    assert "paints.csv" in err and "SHA-256" in err
    assert not (tmp_path / "after").exists()


def test_relight_needs_the_scene_folder_of_a_sample_with_csv_spectra(source, tmp_path, capsys):
    """The sample names its CSV relative to the scene file's folder; without --scene-dir the
    file cannot be found (and verified), so relight refuses in one line naming the option."""
    sample, _ = source
    rc = main(["relight", str(sample), "--light", "0=planck:3000K", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "\n" not in err and "--scene-dir" in err and "paints.csv" in err, err
    assert not (tmp_path / "o").exists()
    rc, err = _relight(sample, tmp_path / "o", capsys)  # --scene-dir: the folder of the CSV
    assert rc == 0, err
    relit = read_meta(tmp_path / "o").raw["spectrum_files"]
    assert [(f["spectrum"], f["file"]) for f in relit] == [
        ("csv:paints.csv#paint [%]", "paints.csv")
    ]


def test_a_scene_dir_cannot_lead_a_recorded_name_outside_it(source, tmp_path, capsys):
    """A recorded name resolves inside --scene-dir only, as a scene file's names do: a folder
    without the CSV is refused in one line (nothing read from elsewhere)."""
    sample, _ = source
    empty = tmp_path / "elsewhere"
    empty.mkdir()
    rc = main(
        ["relight", str(sample), "--light", "0=planck:3000K", "--out", str(tmp_path / "o"),
         "--scene-dir", str(empty)]
    )  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "\n" not in err and "not found" in err, err


def test_a_power_in_the_documented_range_prints_one_line_at_most(source, tmp_path):
    """``--power 1e20`` lies inside the documented range: its float32 overflow warnings went
    to stderr before the result; now stderr holds the one-line result or refusal alone. Run in
    its own process, as a user would (pytest would capture the warnings of an in-process run)."""
    sample, _ = source
    args = ["relight", str(sample), "--light", "0=planck:3000K", "--power", "0=1e20"]
    args += ["--out", str(tmp_path / "bright"), "--scene-dir", str(sample.parent.parent)]
    proc = subprocess.run(
        [sys.executable, "-P", "-m", "spectrinsic", *args],
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, "PYTHONPATH": str(Path(spectrinsic.__file__).parents[1])},
        timeout=300,
    )
    err = proc.stderr.strip()
    assert proc.returncode in (0, 2) and len(err.splitlines()) == 1, err
    assert "Warning" not in err and ("wrote" in err if proc.returncode == 0 else "error" in err)


def test_on_the_fly_relighting_reads_the_csv_from_the_scene_dir(source):
    """The loaders' relighting (RandomRelight) takes the scene folder as relight does: with it
    the layers are those of the CSV reflectance; without it, a one-line refusal."""
    from spectrinsic.errors import DatasetError
    from spectrinsic.gt_export.relight.augment import RandomRelight

    sample, csv = source
    with pytest.raises(DatasetError, match="--scene-dir"):
        RandomRelight(seed=0, cameras=False)(sample, 0)
    layers = RandomRelight(seed=0, cameras=False, scene_dir=str(csv.parent))(sample, 0)
    assert read_meta(sample).raw["materials"]["0"] == "csv:paints.csv#paint [%]"
    from spectrinsic.gt_export.dataset.loader import load_sample

    # reflectance does not depend on the light: the CSV read again gives the stored layer
    np.testing.assert_allclose(layers["reflectance"], load_sample(sample)["reflectance"], atol=1e-6)
