"""Issue 31, tried as a new user would: a generated set with two-light samples, a dataset from
the user's own YAML scene and a relit sample each go through ``check`` (rc 0) and ``evaluate``
(rc 0, REPORT.md naming the dataset and its config hash); a refused evaluation leaves nothing.
Scene-file samples are labelled from the scene: id from its name, lights named by their
spectrum, metals by their η/k table, a condition in the gallery."""

from __future__ import annotations

import json
import shutil

import pytest

from spectrinsic.cli import main

pytestmark = pytest.mark.slow

TINY = ["--preset", "preview", "--resolution", "16x16", "--workers", "1"]
#: A user's own scene: a gold plate on cloth, two unnamed lights of different colours.
GOLD = """\
format: 1
name: gold-on-cloth
materials:
  cloth: "munsell:5B 5/8"
  ground: "flat:0.5"
  gold: {kind: conductor, metal: Au, roughness: 0.1}
meshes:
  - name: plate
    vertices: [[-0.3, -0.2, 0], [0.3, -0.2, 0], [0.3, 0.2, 0.3], [-0.3, 0.2, 0.3]]
    faces: [[0, 1, 2], [0, 2, 3]]
    material: gold
  - name: ground
    vertices: [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]
    faces: [[0, 1, 2], [0, 2, 3]]
    face_materials: [[cloth, 1], [ground, 1]]
lights:
  - {kind: point, spectrum: "planck:2800K", power: 4.0, position: [1, -1, 2]}
  - {kind: point, spectrum: "cie:FL2", power: 3.0, position: [-1, -1, 2]}
camera: {origin: [0.6, -1.2, 1.0], target: [0, 0, 0.1], width: 16, height: 16}
"""


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    out = tmp_path_factory.mktemp("gen") / "set"
    args = ["-q", "dataset", *TINY, "--generator", "objects-on-ground", "--count", "4"]
    assert main([*args, "--seed", "5", "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def own_scene(tmp_path_factory):
    root = tmp_path_factory.mktemp("own")
    (root / "still-life.yaml").write_text(GOLD)
    out = root / "set"
    args = ["-q", "dataset", *TINY, "--scenes", str(root / "still-life.yaml")]
    assert main([*args, "--out", str(out)]) == 0
    return out


def _meta(folder):
    return json.loads((folder / "meta.json").read_text())


def _checks_and_evaluates(dataset, out, capsys, *, preview=True):
    capsys.readouterr()
    assert main(["-q", "check", str(dataset)]) == 0
    assert "ok: " in capsys.readouterr().out
    assert (
        main(
            [
                "-q",
                "evaluate",
                "--dataset",
                str(dataset),
                "--out",
                str(out),
                "--methods",
                "image-as-reflectance",
                "--no-figures",
            ]
        )
        == 0
    )
    report = (out / "REPORT.md").read_text()
    scored = json.loads((out / "scored.json").read_text())
    assert "## What was scored" in report and f"* dataset: `{dataset.resolve().name}`" in report
    assert str(dataset.resolve().parent) not in report  # issue 44: no absolute path written
    assert scored["config_hash"] and scored["config_hash"] in report
    if preview:  # a preview set (its manifest names the preset) is scored with a warning
        assert "preview-grade" in report
    return report, scored


def test_a_generated_set_with_two_light_samples_checks_and_evaluates(generated, tmp_path, capsys):
    conditions = {p.name.rsplit("__", 1)[1] for p in generated.glob("*__v0__*")}
    assert "two-colour" in conditions  # the condition the library's enum refused
    report, scored = _checks_and_evaluates(generated, tmp_path / "ev", capsys)
    manifest = json.loads((generated / "manifest.json").read_text())
    assert scored["config_hash"] == manifest["config_hash"] and scored["n_scored"] == 4
    assert scored["groups"].get("2L", 0) >= 1 and "| 2L" in report
    card = (generated / "DATASET.md").read_text()
    assert "## Intended use" in card and "## Licence" in card and "## Citation" in card


def test_own_scene_is_labelled_from_the_scene_and_evaluates(own_scene, tmp_path, capsys):
    (folder,) = [p for p in own_scene.iterdir() if (p / "meta.json").is_file()]
    assert folder.name == "gold-on-cloth__v0__file"  # the scene's name, not the file's
    meta = _meta(folder)
    assert [light["name"] for light in meta["lights"]] == ["planck:2800K", "cie:FL2"]
    assert "metal:Au" in meta["materials"].values()
    assert "flat:0" not in meta["materials"].values()
    gallery = (own_scene / "gallery.json").read_text()
    assert '"condition":"two-colour"' in gallery.replace(" ", "")
    _, scored = _checks_and_evaluates(own_scene, tmp_path / "ev", capsys)
    assert scored["groups"] == {"2L": 1}


def test_a_relit_sample_checks_and_evaluates(tmp_path, capsys):
    data = tmp_path / "set"
    only = "obj-apple__v0__two-colour-a"
    # the default preset: its reference image (bands31) is one the stored transport relights
    # (preview's spectral reference is refused, tests/gt_export/relight/test_relit_reference.py)
    small = ["--preset", "default", "--resolution", "16x16", "--spp", "2", "--workers", "1"]
    args = ["-q", "dataset", *small, "--only", only, "--store-transport", "--out", str(data)]
    assert main(args) == 0
    relit = tmp_path / "relit"
    leds = ["--light", "0=cie:LED-RGB1", "--light", "1=cie:LED-B3"]
    assert main(["-q", "relight", str(data / only), *leds, "--out", str(relit)]) == 0
    _, scored = _checks_and_evaluates(relit, tmp_path / "ev", capsys, preview=False)
    assert scored["config_hash"] == _meta(relit)["config_hash"] and scored["n_scored"] == 1
    # its condition is its new lights', not the two-colour-a its scene metadata still names
    from spectrinsic.gt_export.dataset.gallery import _sample_entry
    from spectrinsic.gt_export.sample.meta import read_meta
    from spectrinsic.scenes.lighting import describe_lighting

    entry = _sample_entry(relit, read_meta(relit), None)
    assert entry["condition"] == describe_lighting(_meta(relit)["lights"]).family
    assert entry["condition"] != "two-colour-a"


def test_a_refused_evaluation_leaves_no_output(generated, tmp_path, capsys):
    broken = tmp_path / "broken"
    shutil.copytree(generated, broken)
    victim = sorted(broken.glob("*__v0__*"))[-1] / "meta.json"
    meta = json.loads(victim.read_text())
    meta["lights"] = []
    victim.write_text(json.dumps(meta))
    out = tmp_path / "ev"
    capsys.readouterr()
    assert main(["-q", "evaluate", "--dataset", str(broken), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and victim.parent.name in err
    assert not out.exists()


def test_the_contact_sheet_shows_the_denoised_image_at_tile_size(generated):
    from PIL import Image

    from spectrinsic.gt_export.dataset.contact_sheet import TILE, _fit
    from spectrinsic.gt_export.sample import sample_dirs

    first = sample_dirs(generated)[0]
    layers = _meta(first)["layers"]
    with Image.open(generated / "contact_sheet.png") as sheet:
        shown = sheet.convert("RGB").crop((0, 0, TILE, TILE))

    def tile(layer):
        with Image.open(first / layers[layer]["preview"]) as img:
            fitted = _fit(img.convert("RGB"), Image.Resampling)
        canvas = Image.new("RGB", (TILE, TILE), (255, 255, 255))
        canvas.paste(fitted, ((TILE - fitted.width) // 2, (TILE - fitted.height) // 2))
        return canvas

    assert shown.tobytes() == tile("image_denoised").tobytes()  # 16 px enlarged to the tile
    assert shown.tobytes() != tile("image").tobytes()  # not the raw, noisy image
