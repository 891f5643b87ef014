"""Benchmark of the shading ground truth against a converged render.

One room of the default set (``room-living``, view 1, white light) is rendered as the
``default`` preset renders it, and again at 4× its spp in 4 batches as the reference (16×
before the default preset went to 64 spp; ``bench_crop_reference`` has the converged one). Per
pixel, the relative error ``‖s − s_ref‖ / ‖s_ref‖`` of the stored (denoised) shading and of the
raw Monte Carlo shading is reported as measured (median, p95, RMS) and with the reference's own
noise removed in quadrature: per pixel (noisy, since each pixel's reference noise is itself
estimated from 4 batches) and over the image (``rms_corrected = sqrt(mean err² − mean se_ref²)``,
unbiased). Where the reference's own noise exceeds the estimate's error, the per-pixel
corrected figures read 0: the estimate is then closer to the truth than the reference is. Plain path tracing at equal wall time is the raw shading with the spp
scaled by the time ratio (error ∝ 1/√spp). The time of a whole default set is extrapolated from
one sample of each kind (objects, rooms with one and two lights).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from ..gt_export.layers import LayerSettings, compute_ground_truth
from ..pipeline.presets import get_preset
from ..render import render_batches
from ..scenes.library import build
from ..spectra.reconstruction import relative_error

REFERENCE_FACTOR = 4
SCENE, VIEW, CONDITION = "room-living", 1, "white"


def _render(
    cfg: Any, scene: Any, *, spp: int, batches: int, seed: int, modes: tuple[str, ...] | None = None
) -> tuple[Any, float]:
    start = time.perf_counter()
    settings = cfg.render.with_options(
        spp=spp, batches=batches, max_batches=None, modes=modes or cfg.render.modes
    )
    result = render_batches(scene, settings, seed=seed)
    return result, time.perf_counter() - start


def _errors(
    estimate: np.ndarray, reference: np.ndarray, ref_se: np.ndarray, valid: np.ndarray
) -> dict[str, float]:
    err = relative_error(estimate, reference, where=valid)[valid]  # Eq. 5.7 per pixel
    corrected = np.sqrt(np.clip(err**2 - ref_se[valid] ** 2, 0.0, None))
    return {
        "median": float(np.median(err)),
        "p95": float(np.percentile(err, 95)),
        "rms": float(np.sqrt(np.mean(err**2))),
        "median_corrected": float(np.median(corrected)),
        "p95_corrected": float(np.percentile(corrected, 95)),
        "rms_corrected": float(np.sqrt(max(np.mean(err**2) - np.mean(ref_se[valid] ** 2), 0.0))),
    }


def _sample_seconds(cfg: Any, name: str, view: int, condition: str) -> float:
    scene = build(name, view=view, condition=condition, seed=0, width=cfg.width, height=cfg.height)
    start = time.perf_counter()
    result, _ = _render(cfg, scene, spp=cfg.render.spp, batches=cfg.render.batches, seed=1)
    compute_ground_truth(
        scene, result, LayerSettings(cameras=cfg.resolved_cameras(), denoise=cfg.denoise)
    )
    return time.perf_counter() - start


def run(out_dir: Path) -> dict[str, Any]:
    cfg = get_preset("default")
    scene = build(SCENE, view=VIEW, condition=CONDITION, seed=0, width=cfg.width, height=cfg.height)
    noisy, t_render = _render(cfg, scene, spp=cfg.render.spp, batches=cfg.render.batches, seed=1)
    start = time.perf_counter()
    gt = compute_ground_truth(scene, noisy, LayerSettings(denoise=True))
    t_gt = time.perf_counter() - start
    # the shading needs only the cube: the reference renders nothing else
    reference, t_ref = _render(
        cfg, scene, spp=REFERENCE_FACTOR * cfg.render.spp, batches=4, seed=7, modes=("bands31",)
    )
    ref = compute_ground_truth(scene, reference)
    valid = (ref.layers["shading_grey"].data > 0) & (gt.layers["shading_grey"].data > 0)
    ref_se = ref.layers["noise_shading_raw"].data
    s_ref = ref.layers["shading"].data
    raw = _errors(gt.layers["shading_raw"].data, s_ref, ref_se, valid)
    ours = _errors(gt.layers["shading"].data, s_ref, ref_se, valid)
    high = (
        compute_ground_truth(scene, noisy, LayerSettings(denoise=True), denoise_quality="high")
        .layers["shading"]
        .data
    )
    time_ratio = (t_render + t_gt) / t_render
    equal_time_raw = {k: v / np.sqrt(time_ratio) for k, v in raw.items()}
    kinds = {
        "object": _sample_seconds(cfg, "obj-apple", 0, "two-colour-a"),
        "room_one_light": _sample_seconds(cfg, "room-living", 0, "white"),
        "room_two_lights": _sample_seconds(cfg, "room-living", 0, "two-colour-a"),
    }
    # the default layout: 32 object samples, 36 room samples, half of each with two lights
    set_minutes = (
        32 * kinds["object"] + 18 * kinds["room_one_light"] + 18 * kinds["room_two_lights"]
    ) / 60
    return {
        "scene": f"{SCENE} view {VIEW} {CONDITION}, {cfg.width}x{cfg.height}",
        "default_spp": cfg.render.spp,
        "batches": cfg.render.batches,
        "reference_spp": REFERENCE_FACTOR * cfg.render.spp,
        "render_seconds": t_render,
        "ground_truth_seconds": t_gt,
        "reference_seconds": t_ref,
        "reference_own_noise": ref.noise["shading_raw"],
        "shading_stored_denoised": ours,
        "shading_denoised_high_quality": _errors(high, s_ref, ref_se, valid),
        "shading_raw": raw,
        "shading_raw_at_equal_time": equal_time_raw,
        "accuracy_gain_at_equal_time_rms": equal_time_raw["rms_corrected"]
        / max(ours["rms_corrected"], 1e-12),
        "accuracy_gain_at_equal_time_median_uncorrected": equal_time_raw["median"] / ours["median"],
        "predicted_noise_shading_raw": gt.noise["shading_raw"],
        "seconds_per_sample": kinds,
        "default_set_minutes_estimate": set_minutes,
        "goal": {"median": 0.02, "p95": 0.08, "gain": 5.0, "set_minutes": 20.0},
    }
