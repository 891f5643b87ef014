"""A user's predictions as files score exactly like the same method run in-process."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spectrinsic.decompose.evaluation.evaluate import evaluate
from spectrinsic.decompose.evaluation.predictions import Predictions, read_layer
from spectrinsic.decompose.evaluation.sample_fields import input_image
from spectrinsic.decompose.methods.registry import get_decomposer
from spectrinsic.decompose.report import write_report
from spectrinsic.errors import DatasetError
from spectrinsic.gt_export.formats.exr import write_exr
from spectrinsic.gt_export.formats.png import PNG16_MAX, write_png16
from tests.decompose.evaluation.test_evaluate import _sample

BASELINE = "image-as-reflectance"


def _samples():
    return [
        _sample("obj-a__v0__white", 0, (1, 1, 1), True),
        _sample("room-b__v1__two-colour-a", 2, (0.7, 0.9, 1.0), False),
    ]


def _write_baseline_as_files(root, result_dir):
    """Write the baseline's estimates in the predictions layout, as a user's method would."""
    baseline = get_decomposer(BASELINE)
    for sample in _samples():
        sid = sample["meta"]["sample_id"]
        out = baseline(input_image(sample)[1], np.ones(sample["image"].shape[:2], bool))
        folder = root / sid
        folder.mkdir(parents=True)
        write_exr(folder / "reflectance.exr", {"reflectance": out.reflectance})
        write_exr(folder / "shading.exr", {"shading": out.shading})
    # camera scenarios: copy what the in-process run decomposed (its estimates folder)
    for scenario_dir in (result_dir / "estimates" / BASELINE).iterdir():
        if scenario_dir.name == "srgb":
            continue
        for sample_dir in scenario_dir.iterdir():
            target = root / sample_dir.name / scenario_dir.name
            target.mkdir(parents=True)
            for f in sample_dir.iterdir():
                (target / f.name).write_bytes(f.read_bytes())


def test_predictions_folder_scores_exactly_like_the_builtin_baseline(tmp_path):
    builtin = evaluate(_samples(), tmp_path / "builtin", methods=[BASELINE], seed=5, figures=False)
    write_report(tmp_path / "builtin", builtin)
    root = tmp_path / "mine"
    _write_baseline_as_files(root, tmp_path / "builtin")
    mine = evaluate(
        _samples(),
        tmp_path / "scored",
        methods={BASELINE: Predictions(root, name=BASELINE)},
        seed=5,
        figures=False,
        save_estimates=False,
    )
    write_report(tmp_path / "scored", mine)

    def key(s):
        return (s.sample, s.method, s.scenario, s.layer, s.metric)

    expected = {key(s): s.value for s in builtin.scores}
    got = {key(s): s.value for s in mine.scores}
    assert set(got) == set(expected)
    assert any(k[2].startswith("SC1_") for k in got)  # camera scenarios were scored too
    for k, v in expected.items():
        assert (math.isnan(v) and math.isnan(got[k])) or got[k] == v, k
    for name in (
        "lmse_by_condition.csv",
        "colour_by_condition.csv",
        "lmse_by_scenario.csv",
        "table_3_2_objects.csv",
    ):
        assert (tmp_path / "scored" / name).read_text() == (tmp_path / "builtin" / name).read_text()
    report = (tmp_path / "scored" / "REPORT.md").read_text()
    assert "predictions.Predictions" in report and "`shading_grey`" in report


def test_reflectance_alone_is_completed_from_the_image(tmp_path):
    sample = _samples()[0]
    sid = sample["meta"]["sample_id"]
    image = input_image(sample)[1]
    refl = np.full(image.shape, 0.5, np.float32)
    (tmp_path / sid).mkdir()
    write_exr(tmp_path / sid / "reflectance.exr", {"anything": refl})  # the only layer
    out = Predictions(tmp_path).load(sid, "srgb", image, np.ones(image.shape[:2], bool))
    np.testing.assert_allclose(out.shading, image / 0.5, rtol=1e-6)


def test_png16_linear_and_srgb_encodings(tmp_path):
    codes = np.arange(2 * 3 * 3, dtype=np.uint16).reshape(2, 3, 3) * 3000
    write_png16(tmp_path / "reflectance.png", codes)
    grey = np.array([[0, 65535, 32768], [1, 2, 3]], np.uint16)
    write_png16(tmp_path / "shading.png", grey)
    linear = read_layer(tmp_path, "reflectance", (2, 3), encoding="linear")
    np.testing.assert_array_equal(linear, codes / PNG16_MAX)
    shading = read_layer(tmp_path, "shading", (2, 3), encoding="linear")
    assert shading.shape == (2, 3, 3)
    np.testing.assert_array_equal(shading[..., 2], grey / PNG16_MAX)
    srgb = read_layer(tmp_path, "reflectance", (2, 3), encoding="srgb")
    v = codes[1, 2, 2] / PNG16_MAX  # 51000 / 65535 > 0.04045: IEC 61966-2-1 power branch
    assert srgb[1, 2, 2] == pytest.approx(((v + 0.055) / 1.055) ** 2.4, rel=1e-12)
    with pytest.raises(DatasetError, match=r"expected a reflectance image of shape \(4, 4, 3\)"):
        read_layer(tmp_path, "reflectance", (4, 4), encoding="linear")


def test_missing_and_bad_predictions_are_one_line_errors(tmp_path):
    sample = _samples()[0]
    image = input_image(sample)[1]
    with pytest.raises(DatasetError, match="does not exist"):
        Predictions(tmp_path / "nowhere")
    (tmp_path / "notes.txt").write_text("x")
    with pytest.raises(DatasetError, match="'[^']*notes.txt' is a file, not a folder"):
        Predictions(tmp_path / "notes.txt")
    with pytest.raises(DatasetError, match="no reflectance or shading"):
        Predictions(tmp_path).load("obj-a__v0__white", "srgb", image, np.ones((48, 48), bool))
    assert (
        Predictions(tmp_path).load("obj-a__v0__white", "SC4_x", image, np.ones((48, 48), bool))
        is None
    )
    from PIL import Image

    (tmp_path / "s").mkdir()
    Image.fromarray(np.zeros((48, 48, 3), np.uint8)).save(tmp_path / "s" / "reflectance.png")
    with pytest.raises(DatasetError, match="8 bits per channel; expected 16-bit"):
        Predictions(tmp_path).load("s", "srgb", image, np.ones((48, 48), bool))


def test_cli_predictions_options(tmp_path):
    from spectrinsic.cli import build_parser
    from spectrinsic.cli.evaluate import _methods

    (tmp_path / "mine").mkdir()
    args = build_parser().parse_args(
        ["evaluate", "--predictions", f"ours={tmp_path / 'mine'}", "--png-encoding", "srgb"]
    )
    methods = _methods(args)
    assert list(methods) == ["ours"]  # no bundled method unless --methods asks
    assert methods["ours"].encoding == "srgb" and methods["ours"].name == "ours"
    args = build_parser().parse_args(
        ["evaluate", "--methods", BASELINE, "--predictions", str(tmp_path / "mine")]
    )
    assert list(_methods(args)) == [BASELINE, "mine"]
    args = build_parser().parse_args(
        ["evaluate", "--methods", BASELINE, "--predictions", f"{BASELINE}={tmp_path / 'mine'}"]
    )
    with pytest.raises(DatasetError, match="already used"):
        _methods(args)


def _png_declaring(path, width: int, height: int) -> None:
    """A 16-bit RGB PNG whose IHDR declares *width* x *height* but whose data is a few bytes."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
        )

    ihdr = struct.pack(">IIBBBBB", width, height, 16, 2, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(bytes(64)))
        + chunk(b"IEND", b"")
    )


def _exr_declaring(path, width: int, height: int) -> None:
    """A 4 x 4 EXR whose header's dataWindow is patched to declare *width* x *height*."""
    import struct

    from spectrinsic.gt_export.formats.exr import write_exr

    write_exr(path, {"reflectance": np.zeros((4, 4, 3), np.float32)})
    data = bytearray(path.read_bytes())
    at = data.index(b"dataWindow\x00box2i\x00") + len(b"dataWindow\x00box2i\x00") + 4
    data[at : at + 16] = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    path.write_bytes(bytes(data))


@pytest.mark.parametrize("fmt", ["png", "exr"])
def test_a_prediction_declaring_a_huge_image_is_refused_from_its_header(tmp_path, fmt):
    """Issue 17 item 7: a 0.8 MB PNG declaring 20000^2 took 4.8 GB before its shape was refused.
    The header is read first; the refusal names the declared and the expected size."""
    from spectrinsic.decompose.evaluation.predictions import read_layer

    path = tmp_path / f"reflectance.{fmt}"
    (_png_declaring if fmt == "png" else _exr_declaring)(path, 20000, 20000)
    with pytest.raises(DatasetError, match=r"shape \(4, 4, 3\); its header declares 20000x20000"):
        read_layer(tmp_path, "reflectance", (4, 4), encoding="linear")
