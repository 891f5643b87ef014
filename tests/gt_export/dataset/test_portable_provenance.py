"""No file of a built set holds an absolute path of the machine that built it (the builder's
file system would leak, and a set's provenance would depend on where it was built): every
file is read back and searched for the build's folders, gallery included.

Scene-file sets name their ``csv:`` and ``.spd`` spectra relative to the scene file's folder and
their scene files by name, each with its SHA-256; so two copies of one scene folder build
byte-identical sets with one config hash, and a rerun from the other copy resumes the set
(relight reads the CSVs again from the folder given by ``--scene-dir``:
``test_relight_csv_and_warnings.py``).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from spectrinsic.cli import main
from spectrinsic.gt_export import build_gallery, export_sample
from spectrinsic.gt_export.dataset.build_time import reproducible_bytes
from spectrinsic.gt_export.dataset.card import write_dataset_card
from spectrinsic.gt_export.dataset.manifest import write_manifest


def _absolute_paths(root: Path, folders: list[Path]) -> list[str]:
    """``file: folder`` for every file below *root* whose bytes name one of *folders*."""
    found = []
    for path in sorted(p for p in root.rglob("*") if p.is_file()):
        data = path.read_bytes()
        for folder in folders:
            for spelling in {str(folder), str(folder.resolve()), json_escaped(folder)}:
                if spelling.encode() in data:
                    found.append(f"{path.relative_to(root)}: {folder}")
    return sorted(set(found))


def json_escaped(folder: Path) -> str:
    return str(folder).replace("/", "\\/")


def _build(root: Path, samples, config) -> None:
    for sid, (scene, result) in samples.items():
        export_sample(root, scene, result, sample_id=sid, config=config, seed=1)
    write_manifest(root, config)
    write_dataset_card(root, config=config)
    build_gallery(root)


def test_a_built_set_holds_no_absolute_path(
    tmp_path, one_light_sample, two_light_sample, config, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    root = tmp_path / "ds"
    _build(root, {"one": one_light_sample, "two": two_light_sample}, config)
    assert (root / "index.html").is_file() and (root / "gallery.json").is_file()
    home = Path(os.path.expanduser("~"))
    assert _absolute_paths(root, [tmp_path, home, Path(os.getcwd())]) == []


def test_a_set_with_csv_spectra_holds_no_absolute_path(tmp_path, one_light_sample, config):
    """Through the API, with no scene folder: the CSV is named by its file name."""
    csv = tmp_path / "scene" / "paints.csv"
    csv.parent.mkdir()
    csv.write_text("wavelength [nm],paint [%]\n380,40\n550,60\n780,20\n")
    scene, result = one_light_sample
    first = dataclasses.replace(scene.materials[0], spectrum=f"csv:{csv}#paint [%]")
    scene = dataclasses.replace(scene, materials=(first, *scene.materials[1:]))
    root = tmp_path / "ds"
    _build(root, {"one": (scene, result)}, config)
    assert _absolute_paths(root, [tmp_path]) == []
    (record,) = json.loads((root / "one" / "meta.json").read_text())["spectrum_files"]
    digest = hashlib.sha256(csv.read_bytes()).hexdigest()
    assert (record["spectrum"], record["file"], record["sha256"]) == (
        "csv:paints.csv#paint [%]",
        "paints.csv",
        digest,
    )


# --- three scene files built by the command line, from two copies of their folder ---------

PAINTS = "wavelength [nm],paint [%],lamp [W/m2/nm]\n380,40,1\n550,60,2\n780,20,1.5\n"
YAML = """name: box
materials:
  m: {spectrum: 'csv:spectra/paints.csv#paint [%]'}
meshes:
  - {name: q, vertices: [[-1,-1,0],[1,-1,0],[1,1,0],[-1,1,0]], faces: [[0,1,2],[0,2,3]], material: m}
lights:
  - {kind: point, spectrum: 'csv:spectra/paints.csv#lamp [W/m2/nm]', power: 4, position: [0, 0, 2]}
camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 8, height: 8}
"""
XML = """<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
  </sensor>
  <emitter type="point"><point name="position" x="0" y="0" z="3"/>
    <spectrum name="intensity" filename="lamp.spd"/></emitter>
  <shape type="rectangle"><bsdf type="diffuse">
    <texture type="bitmap" name="reflectance"><string name="filename" value="checker.png"/></texture>
  </bsdf></shape>
  <shape type="sphere"><float name="radius" value="0.4"/><point name="center" x="0" y="0" z="0.5"/>
    <bsdf type="diffuse"><string name="reflectance" value="csv:spectra/paints.csv#paint [%]"/></bsdf>
  </shape>
</scene>
"""


def _checker() -> Image.Image:
    colours = np.array([[230, 40, 25], [20, 90, 200]], np.uint8)
    return Image.fromarray(colours[np.indices((4, 4)).sum(axis=0) % 2])


def _scene_folder(folder: Path) -> list[Path]:
    """A YAML scene with csv: spectra in a subfolder, a Mitsuba XML scene (a bitmap texture,
    a .spd emission, a csv: reflectance) and a GLB with an embedded texture."""
    (folder / "spectra").mkdir(parents=True)
    (folder / "spectra" / "paints.csv").write_text(PAINTS)
    (folder / "box.yaml").write_text(YAML)
    (folder / "lamp.spd").write_text("".join(f"{w} {1 + w / 1000}\n" for w in range(360, 831, 10)))
    _checker().save(folder / "checker.png")
    (folder / "room.xml").write_text(XML)
    v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0.0]])
    material = trimesh.visual.material.PBRMaterial(name="checker", baseColorTexture=_checker())
    visual = trimesh.visual.TextureVisuals(uv=(v[:, :2] + 1) / 2, material=material)
    plane = trimesh.Trimesh(v, [[0, 1, 2], [0, 2, 3]], visual=visual, process=False)
    trimesh.Scene({"plane": plane}).export(folder / "plane.glb")
    return [folder / "box.yaml", folder / "room.xml", folder / "plane.glb"]


BUILD = [
    "--preset",
    "preview",
    "--resolution",
    "8x8",
    "--spp",
    "2",
    "--batches",
    "1",
    "--no-denoise",
]


@pytest.fixture(scope="module")
def two_builds(tmp_path_factory) -> tuple[Path, Path, Path]:
    """The same three scene files built from two copies of their folder (``a``, ``b``), each
    run from its own working folder; returns the temporary root."""
    root = tmp_path_factory.mktemp("portable")
    cwd = os.getcwd()
    try:
        for copy in ("a", "b"):
            files = _scene_folder(root / copy / "scenes")
            os.chdir(root / copy)
            out = root / copy / "ds"
            args = ["-q", "dataset", "--scenes", *map(str, files), *BUILD, "--out", str(out)]
            assert main(args) == 0
    finally:
        os.chdir(cwd)
    return root


@pytest.mark.slow  # two dataset builds of three scenes (about 20 s)
def test_a_set_built_from_scene_files_holds_no_absolute_path(two_builds):
    """YAML with csv: spectra, XML with a bitmap, a .spd and a csv: spectrum, GLB with a
    texture: no file of the set (samples, manifest, card, gallery) names the scene folder, the
    working folder, the home or the data directory."""
    ds = two_builds / "a" / "ds"
    assert {p.name for p in ds.iterdir() if p.is_dir() and "__v0__" in p.name} == {
        "box__v0__file",
        "room__v0__file",
        "plane__v0__file",
    }
    assert (ds / "gallery.json").is_file() and (ds / "DATASET.md").is_file()
    folders = [two_builds, Path(os.path.expanduser("~"))]
    folders += [Path(os.environ["SPECTRINSIC_DATA"])] if os.environ.get("SPECTRINSIC_DATA") else []
    assert _absolute_paths(ds, folders) == []
    meta = json.loads((ds / "box__v0__file" / "meta.json").read_text())
    digest = hashlib.sha256(PAINTS.encode()).hexdigest()
    assert {(r["spectrum"], r["file"], r["sha256"]) for r in meta["spectrum_files"]} == {
        ("csv:spectra/paints.csv#lamp [W/m2/nm]", "spectra/paints.csv", digest),
        ("csv:spectra/paints.csv#paint [%]", "spectra/paints.csv", digest),
    }
    xml = json.loads((ds / "room__v0__file" / "meta.json").read_text())["spectrum_files"]
    assert {r["file"] for r in xml} == {"lamp.spd", "spectra/paints.csv"}
    config = json.loads((ds / "manifest.json").read_text())["config"]
    scenes = json.loads(config["source"])["scenes"]
    assert [s["path"] for s in scenes] == ["box.yaml", "room.xml", "plane.glb"]
    assert all(len(s["sha256"]) == 64 for s in scenes)


@pytest.mark.slow  # two dataset builds of three scenes (about 20 s)
def test_two_copies_of_a_scene_folder_build_byte_identical_sets(two_builds):
    """Built from ``a/`` and ``b/``: one config hash, and every file byte for byte the same,
    meta.json and manifest.json included (no field needs to differ: the out folders share
    their name, which the gallery's title shows), but for the build's time: the card's one
    line of it and the time fields of its record."""
    a, b = two_builds / "a" / "ds", two_builds / "b" / "ds"
    files = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file())
    differ = [str(f) for f in files if reproducible_bytes(a / f) != reproducible_bytes(b / f)]
    assert differ == []
    hashes = {json.loads((d / "manifest.json").read_text())["config_hash"] for d in (a, b)}
    assert len(hashes) == 1


@pytest.mark.slow  # two dataset builds of three scenes (about 20 s)
def test_a_rerun_from_the_other_copy_resumes_the_set(two_builds, capsys):
    """The config hash does not depend on where the scene files lie: the set built from ``a``
    is complete for the same files in ``b`` (nothing rebuilt, no --rebuild asked for)."""
    files = [two_builds / "b" / "scenes" / n for n in ("box.yaml", "room.xml", "plane.glb")]
    ds = two_builds / "a" / "ds"
    before = (ds / "box__v0__file" / "meta.json").stat().st_mtime_ns
    args = ["dataset", "--scenes", *map(str, files), *BUILD, "--out", str(ds)]
    assert main(args) == 0, capsys.readouterr().err
    assert (ds / "box__v0__file" / "meta.json").stat().st_mtime_ns == before


@pytest.mark.slow  # two dataset builds of three scenes (about 20 s)
def test_the_files_export_and_evaluate_write_hold_no_absolute_path(two_builds, tmp_path):
    """The shards, their index and an evaluation's REPORT.md and records name the dataset by
    its folder's name, never by its path."""
    ds = two_builds / "a" / "ds"
    assert main(["-q", "export", str(ds), "--out", str(tmp_path / "shards")]) == 0
    args = ["-q", "evaluate", "--dataset", str(ds), "--methods", "image-as-shading"]
    assert main([*args, "--no-figures", "--out", str(tmp_path / "ev")]) == 0
    assert "* dataset: `ds`" in (tmp_path / "ev" / "REPORT.md").read_text()
    folders = [two_builds, tmp_path, Path(os.path.expanduser("~"))]
    assert _absolute_paths(tmp_path, folders) == []


def _camera_csv() -> str:
    """Three smooth sensor curves (R, G, B) over 380-780 nm, each responding to D65."""
    rows = ["wavelength [nm],R [1],G [1],B [1]"]
    for w in range(380, 781, 10):
        r, g, b = (float(np.exp(-(((w - c) / 40.0) ** 2))) for c in (600, 540, 450))
        rows.append(f"{w},{r:.6f},{g:.6f},{b:.6f}")
    return "\n".join(rows) + "\n"


@pytest.mark.slow  # one dataset build with the camera chain and a relight (about 15 s)
def test_a_camera_csv_given_by_absolute_path_is_named_by_its_file(tmp_path, monkeypatch, capsys):
    """``--camera csv:/abs/cam.csv``: its layers, files, the config and the camera chain's
    record name ``csv:cam.csv``, ``spectrum_files`` keeps its SHA-256, no file of the set holds
    the build's folders, and relight reads the curves again from the working folder (checked
    against that SHA-256: an edited CSV is refused in one line)."""
    (tmp_path / "sensors").mkdir()
    cam = tmp_path / "sensors" / "cam.csv"
    cam.write_text(_camera_csv())
    box = _scene_folder(tmp_path / "scenes")[0]
    (tmp_path / "work").mkdir()
    monkeypatch.chdir(tmp_path / "work")
    ds = tmp_path / "ds"
    args = ["-q", "dataset", "--scenes", str(box), "--resolution", "8x8", "--spp", "2"]
    args += ["--batches", "1", "--no-denoise", "--store-transport", "--camera", f"csv:{cam}"]
    assert main([*args, "--out", str(ds)]) == 0, capsys.readouterr().err
    sample = ds / "box__v0__file"
    meta = json.loads((sample / "meta.json").read_text())
    assert (
        "image_camera/csv:cam.csv" in meta["layers"]
        and "csv:cam.csv" in meta["transport"]["cameras"]
    )
    assert (sample / "camera-cam-csv.exr").is_file()
    digest = hashlib.sha256(cam.read_bytes()).hexdigest()
    assert {"spectrum": "csv:cam.csv", "file": "cam.csv", "sha256": digest} in meta[
        "spectrum_files"
    ]
    assert _absolute_paths(ds, [tmp_path, Path(os.path.expanduser("~"))]) == []
    assert digest in (ds / "manifest.json").read_text()  # the config's sensor_files

    relit = ["relight", str(sample), "--light", "0=planck:3000K", "--scene-dir", str(box.parent)]
    assert main([*relit, "--out", str(tmp_path / "nowhere")]) == 2  # no cam.csv in work/
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "csv:cam.csv" in err and "missing" in err, err
    monkeypatch.chdir(tmp_path / "sensors")  # relight finds cam.csv in the working folder
    assert main([*relit, "--out", str(tmp_path / "relit")]) == 0, capsys.readouterr().err
    again = json.loads((tmp_path / "relit" / "meta.json").read_text())
    assert "image_camera/csv:cam.csv" in again["layers"]
    assert _absolute_paths(tmp_path / "relit", [tmp_path]) == []
    capsys.readouterr()
    cam.write_text(_camera_csv().replace("0.", "0.9", 5))
    assert main([*relit, "--out", str(tmp_path / "edited")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "cam.csv" in err and "SHA-256" in err, err
