"""Benchmark of the decomposers: seconds per 256x256 image (goal: names-shades under 60 s).

The image is a synthetic Mondrian (40 patches, 2 % noise) so that the benchmark needs no
rendered dataset; reflectance LMSE against its exact ground truth is reported beside each time.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from spectrinsic.decompose.metrics import lmse
from spectrinsic.decompose.registry import DECOMPOSERS, get_decomposer
from spectrinsic.decompose.synthetic import mondrian

__all__ = ["run", "SIZE", "GOAL_SECONDS"]

SIZE = 256
#: The goal: names-and-shades under 60 s on a 256x256 image on the 2-core machine.
GOAL_SECONDS = 60.0


def run(out_dir: Path) -> dict[str, Any]:
    """Time every registered decomposer on one 256x256 Mondrian; return JSON-serialisable results."""
    scene = mondrian(SIZE, SIZE, seed=0, n_patches=40, noise=0.02)
    methods: dict[str, Any] = {}
    for name in DECOMPOSERS:
        decomposer = get_decomposer(name)
        start = time.perf_counter()
        result = decomposer(scene.image)
        seconds = time.perf_counter() - start
        methods[name] = {
            "seconds": round(seconds, 3),
            "reflectance_lmse": round(lmse(scene.reflectance, result.reflectance), 5),
            "info": result.info,
        }
    ns = methods["names-shades"]["seconds"]
    return {
        "image": f"{SIZE}x{SIZE} Mondrian, 40 patches, 2% noise, seed 0",
        "methods": methods,
        "names_shades_goal_s": GOAL_SECONDS,
        "names_shades_within_goal": ns < GOAL_SECONDS,
        "names_shades_vs_retinex": round(ns / max(methods["colour-retinex"]["seconds"], 1e-9), 2),
    }
