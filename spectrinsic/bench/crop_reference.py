"""Stored room shading against a converged reference of a crop (issue 20, part 3).

A converged reference of a whole 256² room costs hours; one of a 64 × 64 window of it costs
16 × less per sample per pixel. The window is rendered with the film's crop
(:func:`spectrinsic.render.base.plugins.hdr_film`) by the single traversal, at
:data:`REFERENCE_SPP` samples per pixel in :data:`REFERENCE_BATCHES` independent batches, and
its shading is computed by the very functions of the ground truth
(:func:`spectrinsic.gt_export.layers.compute_ground_truth` on the window's render): its pixels
are the full image's pixels. Its own noise (the per-pixel standard error of the batch mean,
relative) is reported beside the errors, which contain it.

The estimate is the stored ground truth of the same sample at the ``default`` preset (all its
modes, 2 batches, OIDN), cut to the window. Per pixel the relative error
``‖s − s_ref‖ / ‖s_ref‖`` (Eq. 5.7) is summarised over lit surface pixels (median, p95,
RMS), over the *edge* pixels (a surface boundary in the 3 × 3 neighbourhood or a pixel shared
by surfaces: where the denoised shading is worst) and over the interior. Variants of the
denoising are scored on the same render: the round-3 default (every band through OIDN
``fast``, normals not marked clean) and every band through ``high`` with clean normals.

The comparison is fair at edges: estimate and reference use the same box filter and the same
definition of ``W`` on a pixel shared by surfaces (the coverage-weighted mean of
:mod:`~spectrinsic.gt_export.layers.irradiance`), so the *raw* estimate is unbiased there: over the
edge pixels, the sum of its shading over the reference's is 1.002 at 128 spp (1.000 on the
shared pixels alone). What the denoised shading gets wrong at edges is noise OIDN leaves and
blur, not a definition: its signed error's median on edge pixels is within ±1 %.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from ..gt_export.layers import LayerSettings, compute_ground_truth
from ..gt_export.layers.denoise import Guides, denoise_blocks, denoise_rgb
from ..gt_export.layers.irradiance import WhiteRadiance
from ..pipeline.presets import get_preset
from ..render import render_batches
from ..render.algebra.batch_means import batch_seeds, merge_batches
from ..render.algebra.modes import channel_values, get_mode, raw_to_xyz, to_xyz_matrix
from ..render.band_path.traversal import render_traversal
from ..render.result import RenderResult
from ..render.settings import PassRequest
from ..scenes.library import build
from ..scenes.model import Scene
from ..spectra import get_sensors
from ..spectra.reconstruction import relative_error

__all__ = [
    "run",
    "CROP",
    "REFERENCE_SPP",
    "REFERENCE_BATCHES",
    "crop_reference",
    "edge_pixels",
    "shading_errors",
]

SCENE, VIEW, CONDITION = "room-living", 1, "white"
#: ``(x, y, width, height)`` of the window in the 256² image (a wall, furniture and their edges).
CROP = (96, 96, 64, 64)
#: Samples per pixel of the reference, over all its batches (the window's pixels only).
REFERENCE_SPP = 16384
#: Independent batches of the reference (their spread is its own noise: 1.2 % median, 1.8 %
#: p95 at 16384 spp; 16 batches of 1024 took 2–3 minutes on 2 shared cores).
REFERENCE_BATCHES = 16
MODE = "bands31"


def _window(scene: Scene, request: PassRequest, crop: tuple[int, int, int, int]) -> RenderResult:
    """One batch (*request*) of the 31-band cube and the first-hit maps of the *crop*, as a
    render result."""
    mode = get_mode(MODE)
    sensors = get_sensors(mode.sensors)
    (out,), aovs, seconds, variant = render_traversal(
        scene,
        [channel_values(scene, sensors)],
        request,
        aovs=True,
        crop=crop,
    )
    raw = out.image()
    matrix = to_xyz_matrix(mode, scene)
    meta = {
        "spp": request.batch_spp,
        "seed": request.seed,
        "sensors": {MODE: sensors.name},
        "to_xyz": {MODE: matrix.tolist()},
        "variants": {MODE: variant},
        "timings": {"single": {"passes": 1, "seconds": seconds[0], "per_pass": list(seconds)}},
    }
    return RenderResult(
        images={MODE: raw_to_xyz(raw, matrix)}, raw={MODE: raw}, aovs=aovs, meta=meta
    )


def crop_reference(
    scene: Scene,
    *,
    spp: int = REFERENCE_SPP,
    batches: int = REFERENCE_BATCHES,
    seed: int = 7,
    max_depth: int,
    crop: tuple[int, int, int, int] = CROP,
) -> tuple[Any, np.ndarray, float]:
    """Ground truth of the *crop* at *spp* (in *batches*) with paths of *max_depth* (the
    estimate's: a longer path adds light), its edge pixels (:func:`edge_pixels`) and its
    render seconds."""
    start = time.perf_counter()
    parts = [
        _window(scene, PassRequest(spp // batches, s, max_depth), crop)
        for s in batch_seeds(seed, batches)
    ]
    seconds = time.perf_counter() - start
    merged = merge_batches(parts)
    edges = edge_pixels(merged.aovs["material_id"], merged.aovs["coverage"])
    return compute_ground_truth(scene, merged, LayerSettings(cameras=())), edges, seconds


def edge_pixels(material_id: np.ndarray, coverage: np.ndarray) -> np.ndarray:
    """Pixels shared by surfaces (largest coverage below 0.999) or with another material id in
    their 3 × 3 neighbourhood."""
    ids = np.pad(material_id, 1, mode="edge")
    h, w = material_id.shape
    differs = np.zeros((h, w), bool)
    for dy in range(3):
        for dx in range(3):
            differs |= ids[dy : dy + h, dx : dx + w] != material_id
    return differs | (coverage.max(axis=-1) < 0.999)


def shading_errors(
    estimate: np.ndarray,
    reference: np.ndarray,
    valid: np.ndarray,
    edges: np.ndarray,
    reference_se: np.ndarray | None = None,
) -> dict[str, Any]:
    """Median, p95 and RMS of the per-pixel relative error (Eq. 5.7) on *valid* pixels, and
    on the edge and interior pixels among them. With the reference's own relative standard
    error per pixel, also the error with it removed in quadrature (``corrected``: per pixel
    ``sqrt(max(err² − se², 0))``; RMS over the pixels, unbiased)."""
    err = relative_error(estimate, reference, where=valid)

    def summary(mask: np.ndarray) -> dict[str, Any]:
        e = err[mask]
        if e.size == 0:  # no such pixels: nothing to summarise
            return {"median": None, "p95": None, "rms": None, "pixels": 0}
        return {
            "median": float(np.median(e)),
            "p95": float(np.percentile(e, 95)),
            "rms": float(np.sqrt(np.mean(e**2))),
            "pixels": int(mask.sum()),
        }

    out = summary(valid)
    out["edges"] = summary(valid & edges)
    out["interior"] = summary(valid & ~edges)
    if reference_se is not None:
        e, se = err[valid], reference_se[valid]
        net = np.sqrt(np.clip(e**2 - se**2, 0.0, None))
        out["corrected"] = {
            "median": float(np.median(net)),
            "p95": float(np.percentile(net, 95)),
            "rms": float(np.sqrt(max(np.mean(e**2) - np.mean(se**2), 0.0))),
        }
    return out


def _previous_default(radiance: WhiteRadiance, guides: Guides) -> WhiteRadiance:
    """The round-3 denoiser: every band through OIDN ``fast``, normals not marked clean."""
    return radiance.with_bands(
        denoise_blocks(radiance.bands, guides.normals, quality="fast", clean_aux=False)
    )


def _every_band_high(radiance: WhiteRadiance, guides: Guides) -> WhiteRadiance:
    """Every band through OIDN ``high`` with clean normals (about 4× the default's seconds)."""
    return radiance.with_bands(denoise_blocks(radiance.bands, guides.normals, quality="high"))


def _denoised(scene: Scene, noisy: RenderResult) -> dict[str, tuple[np.ndarray, float]]:
    """Shading of each denoising variant on the same render, with its ground-truth seconds."""
    variants: dict[str, dict[str, Any]] = {
        "stored": {},
        "previous_default": {"denoiser": _previous_default},
        "every_band_high": {"denoiser": _every_band_high},
    }
    denoise_rgb(np.zeros((8, 8, 3)))  # OIDN's device starts on its first call: no variant's cost
    out = {}
    for name, kwargs in variants.items():
        start = time.perf_counter()
        gt = compute_ground_truth(scene, noisy, LayerSettings(cameras=(), denoise=True), **kwargs)
        out[name] = (gt.layers["shading"].data, time.perf_counter() - start)
    out["raw"] = (gt.layers["shading_raw"].data, 0.0)
    return out


def _cut(layer: np.ndarray, crop: tuple[int, int, int, int]) -> np.ndarray:
    x, y, w, h = crop
    return layer[y : y + h, x : x + w]


def run(out_dir: Path) -> dict[str, Any]:
    """Errors of the stored shading of the default preset (and of denoising variants) in
    :data:`CROP` against the crop's converged reference, with the reference's own noise."""
    cfg = get_preset("default")
    scene = build(SCENE, view=VIEW, condition=CONDITION, seed=0, width=cfg.width, height=cfg.height)
    start = time.perf_counter()
    noisy = render_batches(scene, cfg.render, seed=1)
    t_render = time.perf_counter() - start
    ref, edges, t_ref = crop_reference(scene, max_depth=cfg.render.max_depth)
    s_ref = ref.layers["shading"].data
    valid = ref.layers["shading_grey"].data > 0
    ref_se = ref.layers["noise_shading_raw"].data
    ref_noise = ref_se[valid]
    scored = {}
    for name, (shading, seconds) in _denoised(scene, noisy).items():
        scored[name] = shading_errors(_cut(shading, CROP), s_ref, valid, edges, ref_se)
        scored[name]["ground_truth_seconds"] = seconds
    return {
        "scene": f"{SCENE} view {VIEW} {CONDITION}, {cfg.width}x{cfg.height}",
        "crop": list(CROP),
        "estimate": {
            "spp": cfg.render.spp,
            "spectral_spp": cfg.render.spectral_spp,
            "batches": cfg.render.batches,
            "render_seconds": t_render,
        },
        "reference": {
            "spp": REFERENCE_SPP,
            "batches": REFERENCE_BATCHES,
            "render_seconds": t_ref,
            "own_noise_median": float(np.median(ref_noise)),
            "own_noise_p95": float(np.percentile(ref_noise, 95)),
            "own_noise_edges_median": float(np.median(ref_se[valid & edges])),
        },
        "shading": scored,
        "goal": {"median": 0.02, "p95": 0.08},
    }
