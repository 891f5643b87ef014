"""``relight`` verifies the CSV spectra it reads again against ``meta.json["spectrum_files"]``,
and prints exactly one line (no arithmetic warnings before it).

A sample whose material is a column of a CSV file was relit after an edit to that CSV with
rc 0, and every layer holding the reflectance changed. Now the file's SHA-256 is checked
against the one recorded at build time, and a mismatch is refused in one line naming the file.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from spectrinsic.cli import main
from spectrinsic.gt_export import export_sample
from spectrinsic.gt_export.sample.meta import read_meta
from spectrinsic.render import RenderSettings
from spectrinsic.render.transport_render import render_transport_batches

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
    transport, result = render_transport_batches(scene, SETTINGS, seed=3)
    sample = export_sample(
        out / "ds", scene, result, sample_id="s", config={"t": 44}, seed=3, transport=transport
    )
    return sample, csv


def _relight(sample: Path, out: Path, capsys) -> tuple[int, str]:
    rc = main(["relight", str(sample), "--light", "0=planck:3000K", "--out", str(out)])
    return rc, capsys.readouterr().err.strip()


def test_the_csv_a_sample_read_is_recorded_with_its_sha256(source):
    sample, csv = source
    files = read_meta(sample).raw["spectrum_files"]
    assert [f["column"] for f in files] == ["paint [%]"]
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


def test_a_power_in_the_documented_range_prints_one_line_at_most(source, tmp_path, capsys):
    """``--power 1e20`` lies inside the documented range: its float32 overflow warnings went
    to stderr before the result; now stderr holds at most the one-line result or refusal."""
    sample, _ = source
    rc = main(
        ["relight", str(sample), "--light", "0=planck:3000K", "--power", "0=1e20",
         "--out", str(tmp_path / "bright")]
    )  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert rc in (0, 2) and err.count("\n") == 0 and "RuntimeWarning" not in err, err
