"""Scene files whose spectra come from CSV files or are written inline (issue 32)."""

from __future__ import annotations

import hashlib
import json

import numpy as np
import pytest
import yaml

from spectrinsic.cli import main
from spectrinsic.errors import SceneError
from spectrinsic.scenes import load_scene, save_scene

WL = np.arange(360.0, 831.0)  # the 1 nm CIE grid: colour-science interpolates nothing
PAINT = 0.1 + 0.7 / (1 + np.exp(-(WL - 590) / 20))
LAMP = 1.0 + 0.002 * (WL - 360)


@pytest.fixture
def folder(tmp_path, make_plane):
    """A scene folder: plane.yaml, its spectra in spectra/measured.csv."""
    (tmp_path / "spectra").mkdir()
    rows = [f"{w:g},{100 * p:.6f},{q:.6f}" for w, p, q in zip(WL, PAINT, LAMP)]
    csv = "wavelength [nm],paint [%],lamp [W/m2/nm]\n" + "\n".join(rows) + "\n"
    (tmp_path / "spectra" / "measured.csv").write_text(csv)
    path = save_scene(make_plane("munsell:5R 4/14", "planck:3000K", size=6), tmp_path / "p.yaml")
    return tmp_path, path


def edit(path, materials=None, light=None):
    """Rewrite the scene file with new material and light spectra."""
    data = yaml.safe_load(path.read_text())
    data["lights"][0].setdefault("direction", [0.0, 0.0, -1.0])  # save_scene leaves it out
    if materials is not None:
        data["materials"]["plane"] = materials
    if light is not None:
        data["lights"][0]["spectrum"] = light
    path.write_text(yaml.safe_dump(data))
    return path


def test_csv_and_inline_spectra_load_with_resolved_names(folder):
    root, path = folder
    edit(path, "csv:spectra/measured.csv#paint", {"wavelengths": [380, 780], "values": [1, 2]})
    scene = load_scene(path)
    csv = root.resolve() / "spectra" / "measured.csv"
    assert scene.materials[0].spectrum == f"csv:{csv}#paint"
    assert scene.lights[0].spectrum.startswith("inline:illuminant:380.0=1.0,780.0=2.0")


@pytest.mark.parametrize(
    ("ref", "expected"),
    [
        ("csv:../outside.csv#paint", "leads outside the scene's folder"),
        ("csv:/etc/passwd#root", "absolute path '/etc/passwd' not allowed"),
        ("csv:spectra/none.csv#paint", "spectrum file 'spectra/none.csv' not found"),
        ("csv:spectra/measured.csv#lamp", "is an illuminant spectrum; expected a reflectance"),
        ({"wavelengths": [400, 700], "values": [0.5, 1.5]}, "reflectance 1.5 > 1"),
    ],
)
def test_bad_spectrum_references_are_refused_in_one_line(folder, ref, expected):
    root, path = folder
    (root.parent / "outside.csv").write_text("wl,paint [1]\n380,0.5\n780,0.5\n")
    edit(path, ref)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert expected in str(info.value) and "materials" in str(info.value)
    assert "\n" not in str(info.value)


def test_a_bad_csv_in_a_scene_stops_render_with_rc_2_before_any_work(folder, capsys):
    root, path = folder
    text = (root / "spectra" / "measured.csv").read_text().replace("\n400,", "\n300,", 1)
    (root / "spectra" / "measured.csv").write_text(text)
    edit(path, "csv:spectra/measured.csv#paint")
    assert main(["render", str(path), "--out", str(root / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert "measured.csv: row 42, column 'wavelength [nm]': wavelength 300 nm follows" in err
    assert len(err.splitlines()) == 1 and not (root / "out").exists()


def test_a_scene_with_csv_spectra_renders_their_exact_reflectance(folder):
    """The reflectance layer equals the CSV's spectrum integrated by colour-science (D65,
    CIE 1931 2°, linear RGB of the working space meta.json records: ACEScg by default) within
    1e-5, and meta.json records the file's SHA-256."""
    import colour

    from spectrinsic.gt_export import load_sample

    root, path = folder
    edit(path, "csv:spectra/measured.csv#paint", "csv:spectra/measured.csv#lamp")
    out = root / "out"
    args = ["--ground-truth", "--preset", "preview", "--spp", "2", "--out", str(out)]
    assert main(["-q", "render", str(path), *args]) == 0
    (sample,) = [p.parent for p in out.glob("*/meta.json")]
    loaded = load_sample(sample)
    sd = colour.SpectralDistribution(dict(zip(WL, np.round(PAINT * 100, 6) / 100)))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(cmfs.shape)
    xyz = colour.sd_to_XYZ(sd, cmfs, d65, method="Integration") / 100
    space = loaded["meta"]["working_space"]["colourspace"]
    expected = colour.XYZ_to_RGB(xyz, space, apply_cctf_encoding=False)
    refl = loaded["reflectance"].reshape(-1, 3)
    assert np.abs(refl - expected).max() < 1e-5
    meta = json.loads((sample / "meta.json").read_text())
    digest = hashlib.sha256((root / "spectra" / "measured.csv").read_bytes()).hexdigest()
    assert {r["column"] for r in meta["spectrum_files"]} == {"paint", "lamp"}
    assert {r["sha256"] for r in meta["spectrum_files"]} == {digest}


def test_a_material_map_takes_csv_paths_from_its_folder_and_inline_spectra(folder):
    from spectrinsic.cli.dataset_source import material_map
    from spectrinsic.errors import DatasetError

    root, _ = folder
    path = root / "map.yaml"
    inline = {"wavelengths": [400, 700], "values": [0.2, 0.3]}
    path.write_text(yaml.safe_dump({"paint": "csv:spectra/measured.csv#paint", "clay": inline}))
    mapping = material_map(str(path))
    assert mapping["paint"] == f"csv:{(root / 'spectra' / 'measured.csv').resolve()}#paint"
    assert mapping["clay"] == "inline:reflectance:400.0=0.2,700.0=0.3"
    path.write_text(yaml.safe_dump({"paint": "csv:../x.csv#paint"}))
    with pytest.raises(DatasetError, match="paint: path '../x.csv' leads outside"):
        material_map(str(path))
