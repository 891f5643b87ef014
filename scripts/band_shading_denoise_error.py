"""How far the denoised band shading is from the truth (issue 30): ``shading_bands`` of a
dataset-like render (low spp, OIDN-denoised as ``dataset`` does,
:func:`spectrinsic.gt_export.layers.denoise.denoise_white_radiance`: three broad bands times per-band
shares, guided by normals and depth) against the raw band shading of a high-spp render of the
same room (another seed, so its own noise is independent and small).

Usage: python -P scripts/band_shading_denoise_error.py OUT.json [--rooms N] [--size S]
       [--spp P] [--ref-spp R] [--seed K]

Per room and band k, over the pixels valid in both renders and lit in the reference:
``RMSE_k / mean(reference_k)`` (relative RMSE), for the denoised and for the raw low-spp band
shading; per room the median over the 31 bands; over rooms median and max. The reference's
own noise (about sqrt(P/R) of the raw error) bounds how small the figure can be. Writes
OUT.json and prints a markdown table.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from spectrinsic.gt_export.layers import LayerSettings, compute_ground_truth
from spectrinsic.gt_export.layers.spectral_intrinsics import light_family
from spectrinsic.render import RenderSettings, render_batches
from spectrinsic.scenes.generators import generate
from spectrinsic.scenes.generators.base import GeneratorOptions


def band_errors(test: np.ndarray, reference: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """``(K,)`` relative RMSE per band of *test* against *reference* over *valid* pixels.

    >>> ref = np.ones((2, 2, 3)); valid = np.ones((2, 2), bool)
    >>> band_errors(ref * 1.1, ref, valid).round(6).tolist()
    [0.1, 0.1, 0.1]
    """
    t, r = np.asarray(test, np.float64)[valid], np.asarray(reference, np.float64)[valid]
    rmse = np.sqrt(((t - r) ** 2).mean(axis=0))
    return rmse / np.maximum(np.abs(r).mean(axis=0), np.finfo(float).tiny)


def _room(index: int, args: argparse.Namespace) -> dict:
    options = GeneratorOptions(width=args.size, height=args.size)
    scene = generate("rooms", root_seed=args.seed, index=index, view=0, options=options)
    base = {"max_depth": 5, "modes": ("bands31", "rgb3"), "per_light": True, "share_mode": "rgb3"}
    low = render_batches(scene, RenderSettings(args.spp // 2, batches=2, **base), seed=index + 1)
    ref = render_batches(
        scene, RenderSettings(args.ref_spp // 2, batches=2, **base), seed=index + 101
    )
    denoised = compute_ground_truth(
        scene, low, LayerSettings(cameras=(), denoise=True, spectral_layers=True)
    )
    truth = compute_ground_truth(
        scene, ref, LayerSettings(cameras=(), denoise=False, spectral_layers=True)
    )
    raw = compute_ground_truth(
        scene, low, LayerSettings(cameras=(), denoise=False, spectral_layers=True)
    )
    reference = truth.layers["shading_bands"].data
    valid = (
        (reference.sum(axis=-1) > 0)
        & (denoised.layers["shading_bands"].data.sum(axis=-1) > 0)
        & (raw.layers["shading_bands"].data.sum(axis=-1) > 0)
    )
    den = band_errors(denoised.layers["shading_bands"].data, reference, valid)
    noisy = band_errors(raw.layers["shading_bands"].data, reference, valid)
    return {
        "index": index,
        "family": light_family(li.spectrum for li in scene.lights),
        "pixels": int(valid.sum()),
        "denoised_median_over_bands": float(np.median(den)),
        "denoised_max_over_bands": float(den.max()),
        "raw_median_over_bands": float(np.median(noisy)),
        "denoised_per_band": den.tolist(),
        "raw_per_band": noisy.tolist(),
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out", type=Path)
    p.add_argument("--rooms", type=int, default=4)
    p.add_argument("--size", type=int, default=48)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--ref-spp", type=int, default=512)
    p.add_argument("--seed", type=int, default=30)
    args = p.parse_args(argv)
    start = time.perf_counter()
    rows = [_room(i, args) for i in range(args.rooms)]
    den = [r["denoised_median_over_bands"] for r in rows]
    raw = [r["raw_median_over_bands"] for r in rows]
    summary = {
        "rooms": args.rooms,
        "size": args.size,
        "spp": args.spp,
        "ref_spp": args.ref_spp,
        "seed": args.seed,
        "denoised_median": float(np.median(den)),
        "denoised_max": float(np.max(den)),
        "raw_median": float(np.median(raw)),
        "raw_max": float(np.max(raw)),
        # the reference's own noise, from the raw error scaled by sqrt(spp / ref_spp)
        "reference_noise_estimate": float(np.median(raw) * np.sqrt(args.spp / args.ref_spp)),
        "seconds": time.perf_counter() - start,
    }
    args.out.write_text(json.dumps({"summary": summary, "rooms": rows}, indent=1))
    print("| room | family | denoised (median over bands) | max band | raw |")
    print("|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['index']} | {r['family']} | {100 * r['denoised_median_over_bands']:.2f} % | "
            f"{100 * r['denoised_max_over_bands']:.2f} % | {100 * r['raw_median_over_bands']:.2f} % |"
        )
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
