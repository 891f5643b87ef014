"""Issue 36, cause 3: ``relight`` verifies what it reads before using it.

A source sample whose ``transport.exr`` has 200 flipped bytes, or whose ``scene.json`` has one
light's power edited (still valid JSON), was relit with rc 0 and written with fresh SHA-256s,
so ``check`` could no longer find the damage. Now each is refused in one line naming the file,
before anything is written; and the transport's header (declared size and channels) is checked
against the sample's ``meta.json`` record before any pixel is decoded.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from spectrinsic.cli import main
from spectrinsic.errors import DatasetError
from spectrinsic.gt_export.sample.meta import read_meta
from spectrinsic.gt_export.sample.transport_exr import TRANSPORT_NAME
from spectrinsic.render import RenderSettings
from tests.gt_export._builders import render_transport_sample

SETTINGS = RenderSettings(spp=2, modes=("rgb3",), batches=2, max_depth=3)


@pytest.fixture(scope="module")
def source(tmp_path_factory, make_room) -> Path:
    """A two-light room sample (8x8) stored with its transport."""
    out = tmp_path_factory.mktemp("relight-checks")
    scene = make_room(size=8)
    sample, _, _ = render_transport_sample(
        out, scene, SETTINGS, seed=3, sample_id="room__v0__two", config={"t": 36}
    )
    return sample


@pytest.fixture
def sample(source, tmp_path) -> Path:
    """A private copy of the source sample, free to damage."""
    return Path(shutil.copytree(source, tmp_path / source.name))


def _relight(sample: Path, out: Path, capsys) -> tuple[int, str]:
    rc = main(["relight", str(sample), "--light", "0=planck:3000K", "--out", str(out)])
    return rc, capsys.readouterr().err.strip()


def test_a_sound_sample_still_relights(sample, tmp_path, capsys):
    rc, _ = _relight(sample, tmp_path / "relit", capsys)
    assert rc == 0 and (tmp_path / "relit" / "meta.json").is_file()


def test_flipped_bytes_in_the_transport_are_refused_naming_the_file(sample, tmp_path, capsys):
    path = sample / TRANSPORT_NAME
    data = bytearray(path.read_bytes())
    start = len(data) // 2  # inside the pixel data, past the header
    data[start : start + 200] = bytes(b ^ 0xFF for b in data[start : start + 200])
    path.write_bytes(bytes(data))
    rc, err = _relight(sample, tmp_path / "relit", capsys)
    assert rc == 2 and "\n" not in err
    assert str(path) in err and "SHA-256" in err
    assert not (tmp_path / "relit").exists()


def test_an_edited_light_power_in_scene_json_is_refused(sample, tmp_path, capsys):
    path = sample / "scene.json"
    scene = json.loads(path.read_text())
    scene["lights"][0]["power"] = scene["lights"][0]["power"] * 10  # still valid JSON
    path.write_text(json.dumps(scene))
    rc, err = _relight(sample, tmp_path / "relit", capsys)
    assert rc == 2 and "\n" not in err
    assert str(path) in err and "SHA-256" in err
    assert not (tmp_path / "relit").exists()


def test_the_transport_header_must_declare_the_samples_size_and_channels(sample):
    from spectrinsic.gt_export.relight.checks import check_transport_header, transport_channels

    meta = read_meta(sample).raw
    record, (h, w) = meta["transport"], meta["size"]
    path = sample / TRANSPORT_NAME
    check_transport_header(path, record, (h, w))  # the file as written: accepted
    # 2 lights x rgb3's X, Y, Z: the batch mean, and batch 0's deviation (of 2 batches)
    assert transport_channels(record) == {
        f"{name}.{c}" for j in (0, 1) for name in (f"L{j}_rgb3", f"D{j}_b0_rgb3") for c in "XYZ"
    }
    # the layout before issue 45: every batch in full
    old = {k: v for k, v in record.items() if k != "layout"}
    assert transport_channels(old) == {
        f"L{j}_b{b}_rgb3.{c}" for j in (0, 1) for b in (0, 1) for c in "XYZ"
    }
    with pytest.raises(DatasetError, match=rf"{TRANSPORT_NAME}: declares {w}x{h} pixels"):
        check_transport_header(path, record, (h + 1, w))
    with pytest.raises(DatasetError, match="missing \\['D2_b0_rgb3.X'"):
        check_transport_header(path, {**record, "lights": 3}, (h, w))
    with pytest.raises(DatasetError, match="unexpected \\['D1_b0_rgb3.X'"):
        check_transport_header(path, {**record, "lights": 1}, (h, w))


@pytest.mark.parametrize("power", ["inf", "1e308", "1e400", "nan", "1e-300"])
def test_a_power_that_overflows_or_vanishes_is_refused_in_one_line(source, tmp_path, capsys, power):
    """Cause 5: these gave all-NaN images with rc 0 and ``"power": "inf"`` in meta.json."""
    out = tmp_path / "relit"
    args = ["relight", str(source), "--light", "0=planck:3000K", "--power", f"0={power}"]
    assert main([*args, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "light power" in err and "[1e-20, 1e+20]" in err
    assert not out.exists()


def test_a_relit_render_that_is_not_finite_is_refused_before_writing(source):
    import dataclasses

    import numpy as np

    from spectrinsic.gt_export.relight import relit_render
    from spectrinsic.gt_export.relight.checks import check_finite_result

    relit = relit_render(source, {0: "planck:3000K"})
    check_finite_result(relit.result, source)  # a sound relighting passes
    image = relit.result.images["rgb3"].copy()
    image[0, 0, 1] = np.inf
    broken = dataclasses.replace(relit.result, images={**relit.result.images, "rgb3": image})
    with pytest.raises(DatasetError, match="relit image of mode 'rgb3' is not finite"):
        check_finite_result(broken, source)
