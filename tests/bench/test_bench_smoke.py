"""``make bench`` at the tiniest size: every step of the render and decomposer benchmarks runs
and writes the JSON it promises (the numbers are meaningless at this size; ``make bench``
measures them)."""

from __future__ import annotations

import json

import pytest

from spectrinsic import bench
from spectrinsic.bench import decompose as bench_decompose
from spectrinsic.bench import render as bench_render


@pytest.fixture
def tiny(monkeypatch):
    """The benchmarks' sizes cut to a few pixels and samples."""
    for name, value in {
        "SIZE": 8,
        "SPP": 1,
        "OVERHEAD_SIZE": 8,
        "OVERHEAD_SPP": 1,
        "REPEATS": 1,
        "TRUTH_FACTOR": 2,
    }.items():
        monkeypatch.setattr(bench_render, name, value)
    monkeypatch.setattr(bench_decompose, "SIZE", 32)  # LMSE needs a 20-pixel window


@pytest.mark.slow
def test_render_and_decompose_benchmarks_write_their_results(tiny, tmp_path, capsys):
    assert bench.main(["--out", str(tmp_path), "--only", "render", "decompose"]) == 0
    render = json.loads((tmp_path / "bench_render.json").read_text())
    assert set(render["passes"]) == set(bench_render.MODES) | {"aovs"}
    assert render["passes"]["bands31"] == 11 and render["passes"]["rgb3"] == 1
    assert all(v > 0 for v in render["seconds_per_pass"].values())
    assert render["equal_time"]["bands31_spp"] == 1 and "8x8" in render["scene"]
    decomposers = json.loads((tmp_path / "bench_decompose.json").read_text())
    assert {"names-shades", "colour-retinex"} <= set(decomposers["methods"])
    assert all(m["reflectance_lmse"] >= 0 for m in decomposers["methods"].values())
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert set(summary) == {"bench_render", "bench_decompose"}
    assert "bench_render:" in capsys.readouterr().out


def test_residual_benchmark_reports_rgb_and_band_shares(monkeypatch, tmp_path):
    from spectrinsic.bench import residual as bench_residual

    monkeypatch.setattr(bench_residual, "ROOMS", 1)
    monkeypatch.setattr(bench_residual, "SIZE", 12)
    monkeypatch.setattr(bench_residual, "SPP", 2)
    assert bench.main(["--out", str(tmp_path), "--only", "residual"]) == 0
    result = json.loads((tmp_path / "bench_residual.json").read_text())
    assert result["band_residual_share"]["max"] < 1e-4 < result["rgb_residual_share"]["max"]
    # the default working space beside linear sRGB, on the same render, as ratios
    assert result["working_space"] == "acescg"
    ratio = result["rgb_residual_share"]["median"] / result["srgb_residual_share"]["median"]
    assert result["default_over_srgb"]["median"] == pytest.approx(ratio)
    cost = result["spectral_exr_cost"]
    assert cost["folder_bytes_with_bands"] > cost["folder_bytes_without_bands"]


@pytest.mark.slow
def test_real_scene_benchmark_compares_the_xml_reader_with_mitsubas_load_file(
    monkeypatch, tmp_path
):
    from spectrinsic.bench import real_scene
    from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml

    monkeypatch.setattr(real_scene, "MESHES", 4)
    scene = load_mitsuba_xml(real_scene.write_interior(tmp_path / "interior"))
    assert len(scene.meshes) == 4 + 1 and len(scene.lights) == 2
    assert sum(len(m.faces) for m in scene.meshes) == 4 * real_scene.FACES_PER_MESH + 2
    assert bench.main(["--out", str(tmp_path), "--only", "real_scene"]) == 0
    result = json.loads((tmp_path / "bench_real_scene.json").read_text())
    assert result["spectrinsic_seconds"] > 0 and result["mitsuba_load_file_seconds"] > 0
    assert result["time_ratio"] == pytest.approx(
        result["spectrinsic_seconds"] / result["mitsuba_load_file_seconds"]
    )


def test_artist_interior_has_the_issues_textures_glass_mirror_and_sun_and_sky(
    monkeypatch, tmp_path
):
    """The benchmark's interior (issue 42) read as `render --approximate` reads it: every box,
    the 20 bitmap textures, the glass, the mirror, and the sunsky as a sun and a sky map."""
    from spectrinsic.bench import artist_interior as bench_interior
    from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))  # the baked sky map
    path = bench_interior.write_interior(tmp_path / "interior", 44, (32, 24), "preview")
    scene = load_mitsuba_xml(path, approximate=True)
    assert len(scene.meshes) == 44 + 4  # the boxes, the floor, two walls, the mirror
    assert (scene.camera.width, scene.camera.height) == (32, 24)
    textured = {m.name for m in scene.meshes if m.texture is not None}
    assert len(list((tmp_path / "interior" / "textures").glob("*.png"))) == 20
    assert len(textured) == 20 + 1  # the 40 non-glass boxes alternate; the floor is textured
    kinds = [scene.materials[m.face_materials[0]] for m in scene.meshes]
    assert sum(m.kind == "dielectric" for m in kinds) == bench_interior.GLASS
    assert sum(m.kind == "conductor" for m in kinds) == 1
    assert sorted(light.kind for light in scene.lights) == ["directional"] + ["envmap"] * 3
    assert any("sunsky" in line for line in scene.metadata["approximated"])
