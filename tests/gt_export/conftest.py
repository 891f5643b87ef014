"""Synthetic render results for gt_export tests (no rendering).

A synthetic sample is physically consistent by construction: at pixel x the spectral radiance is
``Σ_m c_m(x) ρ_m(λ) Σ_l g_l(x) E_l(λ)`` (coverage c, reflectances ρ, per-light geometry g and
unit-luminance SPDs E), integrated on the 1 nm CIE grid into XYZ and into a 31-band cube. The
images are computed here with plain numpy and colour-science data, independently of the
gt_export code under test.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from spectrinsic.render.result import RenderResult
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene

H, W = 12, 16
MATERIALS = ("munsell:5R 4/14", "munsell:5PB 4/10", "colorchecker:dark skin", "flat:0.8")


def coverage_map() -> np.ndarray:
    """(H, W, 4): four material blocks; one anti-aliased column; a background margin."""
    cov = np.zeros((H, W, len(MATERIALS)))
    cov[1:6, 1:7, 0] = 1.0
    cov[1:6, 7, 0] = 0.25  # edge pixel: 25 % material 0, 75 % material 1
    cov[1:6, 7, 1] = 0.75
    cov[1:6, 8:15, 1] = 1.0
    cov[6:11, 1:8, 2] = 1.0
    cov[6:11, 8:15, 3] = 1.0
    cov[6:11, 15, 3] = 0.5  # edge pixel half over background
    return cov


def _grid_and_cmfs() -> tuple[np.ndarray, np.ndarray]:
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    return np.asarray(cmfs.wavelengths, float), np.asarray(cmfs.values, float).T


def make_scene(lights: tuple[str, ...] = ("planck:2800K",)) -> Scene:
    mesh = Mesh(
        name="plane",
        vertices=np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]),
        faces=np.array([[0, 1, 2]]),
        face_materials=np.array([0]),
        object_id=0,
    )
    return Scene(
        name="synthetic",
        meshes=(mesh,),
        materials=tuple(Material(f"m{i}", s) for i, s in enumerate(MATERIALS)),
        lights=tuple(
            Light(
                kind="point",
                spectrum=s,
                power=10.0 + i,
                position=(float(i), 0.0, 2.0),
                name=f"lamp{i}",
            )
            for i, s in enumerate(lights)
        ),
        camera=Camera(origin=(0.0, -3.0, 1.0), target=(0.0, 0.0, 0.0), width=W, height=H),
        metadata={"condition": "synthetic"},
    )


def make_result(
    scene: Scene,
    geometry: np.ndarray | None = None,
    *,
    modes: tuple[str, ...] = ("bands31", "spectral"),
) -> RenderResult:
    """A consistent synthetic render of *scene* (the real record: gt_export reads its typed
    fields, so a renamed field fails here too).

    Parameters
    ----------
    geometry
        ``(L, H, W)`` per-light geometric factor g_l(x) >= 0; default: smooth ramps, light l
        brighter towards one side.
    modes
        Image modes; every mode gets the exact XYZ (``"rgb3"`` a 2 % perturbed copy).
    """
    from spectrinsic.spectra import get_sensors, get_spectrum

    wl, cmf = _grid_and_cmfs()
    n_lights = len(scene.lights)
    if geometry is None:
        yy, xx = np.mgrid[0:H, 0:W] / max(H, W)
        geometry = np.stack(
            [0.2 + 0.8 * (xx if i % 2 == 0 else 1 - xx) * (0.5 + yy) for i in range(n_lights)]
        )
    cov = coverage_map()
    rho = np.stack([get_spectrum(m.spectrum).on(wl) for m in scene.materials])  # (M, W)
    spds = np.stack([get_spectrum(light.spectrum).on(wl) for light in scene.lights])  # (L, W)
    albedo = cov @ rho  # (H, W, Wl)
    per_light_rad = albedo[None] * geometry[..., None] * spds[:, None, None, :]  # (L,H,W,Wl)
    xyz_l = per_light_rad @ cmf.T  # rectangle rule at 1 nm: dλ = 1
    bands = get_sensors("bands:31@400-700")
    band_curves = bands.on(wl)
    cube = per_light_rad.sum(axis=0) @ band_curves.T
    xyz = xyz_l.sum(axis=0)
    images = {}
    for mode in modes:
        images[mode] = (xyz * 1.02 if mode == "rgb3" else xyz).astype(np.float32)
    per_light = tuple(
        {m: (xyz_l[i] * (1.02 if m == "rgb3" else 1.0)).astype(np.float32) for m in modes}
        for i in range(n_lights)
    )
    coverage_sum = cov.sum(axis=-1)
    material_id = np.where(coverage_sum > 0, np.argmax(cov, axis=-1), -1).astype(np.int32)
    normals = np.zeros((H, W, 3), np.float32)
    normals[coverage_sum > 0] = (0.0, 0.0, 1.0)
    aovs = {
        "coverage": cov.astype(np.float32),
        "material_id": material_id,
        "object_id": np.where(material_id >= 0, 0, -1).astype(np.int32),
        "depth": np.where(coverage_sum > 0, 2.5, 0.0).astype(np.float32),
        "normals": normals,
        "mask": coverage_sum > 0.5,
    }
    raw = {"bands31": cube.astype(np.float32)} if "bands31" in modes else {}
    meta = {
        "variants": {"spectral": "synthetic", "bands31": "synthetic"},
        "spp": 1,
        "seed": 0,
        "max_depth": 8,
        "sensors": {"bands31": "bands:31@400-700"},
        "timings": {"total": 0.123},
    }
    return RenderResult(images=images, raw=raw, per_light=per_light, aovs=aovs, meta=meta)


@pytest.fixture
def one_light_sample() -> tuple[Scene, RenderResult]:
    scene = make_scene(("planck:2800K",))
    return scene, make_result(scene)


@pytest.fixture
def two_light_sample() -> tuple[Scene, RenderResult]:
    scene = make_scene(("planck:2800K", "cie:FL11"))
    return scene, make_result(scene, modes=("bands31", "spectral", "rgb3"))


@pytest.fixture
def config() -> dict[str, Any]:
    return {"preset": "test", "width": W, "height": H, "spp": 1, "seed": 7}


@pytest.fixture
def synth() -> Any:
    """The builders above, for tests that need their own variants."""
    from types import SimpleNamespace

    return SimpleNamespace(
        make_scene=make_scene,
        make_result=make_result,
        coverage_map=coverage_map,
        H=H,
        W=W,
        MATERIALS=MATERIALS,
        RenderResult=RenderResult,
    )


@pytest.fixture
def built(tmp_path, two_light_sample, one_light_sample, config):
    """A two-sample dataset with manifest and card."""
    from spectrinsic.gt_export import export_sample, write_dataset_card, write_manifest

    for sid, (scene, result) in (("b-two", two_light_sample), ("a-one", one_light_sample)):
        export_sample(tmp_path, scene, result, sample_id=sid, config=config, seed=11)
    write_manifest(tmp_path, config)
    write_dataset_card(tmp_path, config)
    return tmp_path
