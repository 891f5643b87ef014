"""Benchmark of the decomposers: seconds and peak memory per 400x400 image (issue 23's goal:
names-shades within 10 s and 1 GB on an idle 2-core machine).

The image is a synthetic Mondrian (40 patches, 2 % noise) so that the benchmark needs no
rendered dataset; reflectance LMSE against its exact ground truth is reported beside each time.
Peak memory is what :mod:`tracemalloc` sees (numpy and Python allocations; the graph-cut
library's own C++ buffers are not traced). Each method runs once before it is timed, so
one-time imports (colour-science, scikit-image) are not counted.
"""

from __future__ import annotations

import time
import tracemalloc
from pathlib import Path
from typing import Any

from ..decompose.methods.registry import DECOMPOSERS, get_decomposer
from ..decompose.metrics.scale import lmse
from ..decompose.synthetic import mondrian

__all__ = ["run", "SIZE", "GOAL_SECONDS", "GOAL_BYTES"]

SIZE = 400
#: The goal: names-and-shades within 10 s and 1 GB on a 400x400 image on the 2-core machine.
GOAL_SECONDS = 10.0
GOAL_BYTES = 2**30


def run(out_dir: Path) -> dict[str, Any]:
    """Time every registered decomposer on one 400x400 Mondrian; return JSON-serialisable results."""
    scene = mondrian(SIZE, SIZE, seed=0, n_patches=40, noise=0.02)
    methods: dict[str, Any] = {}
    for name in DECOMPOSERS:
        decomposer = get_decomposer(name)
        decomposer(scene.image[:64, :64])  # imports and caches outside the timing
        tracemalloc.start()
        start = time.perf_counter()
        result = decomposer(scene.image)
        seconds = time.perf_counter() - start
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        methods[name] = {
            "seconds": round(seconds, 3),
            "peak_traced_bytes": int(peak),
            "reflectance_lmse": round(lmse(scene.reflectance, result.reflectance), 5),
            "info": result.info,
        }
    ns = methods["names-shades"]["seconds"]
    return {
        "image": f"{SIZE}x{SIZE} Mondrian, 40 patches, 2% noise, seed 0",
        "methods": methods,
        "names_shades_goal_s": GOAL_SECONDS,
        "names_shades_goal_bytes": GOAL_BYTES,
        "names_shades_within_goal": (
            ns <= GOAL_SECONDS and methods["names-shades"]["peak_traced_bytes"] <= GOAL_BYTES
        ),
        "names_shades_vs_retinex": round(ns / max(methods["colour-retinex"]["seconds"], 1e-9), 2),
    }
