"""Benchmark of the single band-path traversal against the diagonal passes (issue 20).

One default-preset sample, :data:`SAMPLE` (a room under two coloured lights, the most
expensive class), built with each integrator in one fresh spawned process: first one untimed
build with each (Dr.Jit compiles its kernels), then timed builds alternating between the two,
so both see the same machine load. Reported per integrator: seconds per sample (scene, render,
ground truth, files), Mitsuba seconds per sample and where they go (per pass group), path
traversals per sample (Mitsuba render calls: the progress count of
:func:`spectrinsic.render.count_passes`), and samples per core-hour; and the ratios
single / passes, measured within the run. The machine's load average is recorded: on a shared
machine the absolute figures move with it, the ratios much less.
"""

from __future__ import annotations

import multiprocessing
import os
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from ..pipeline.dataset import _task_scene, build_sample
from ..pipeline.presets import get_preset
from ..pipeline.tasks import SampleTask
from ..render import count_passes, render_batches
from ..render.settings import INTEGRATORS
from ..scenes.library import default_samples

__all__ = ["run", "SAMPLE", "PRESET", "REPEATS"]

#: The sample timed (as in ``make dataset``; its two lights make it the costliest class).
SAMPLE = "room-living__v1__two-colour-a"
PRESET = "default"
#: Timed builds per integrator, alternating.
REPEATS = 2


def _task(work: str, tag: str, integrator: str) -> SampleTask:
    """The sample's task at :data:`PRESET`, its diagonal modes rendered by *integrator* (a
    render setting, not hashed: both give the same pixels to float rounding)."""
    sid = next(s for s in default_samples() if str(s) == SAMPLE)
    data = os.environ.get("SPECTRINSIC_DATA") or None
    config = get_preset(PRESET).with_options(integrator=integrator)
    return SampleTask.planned(sid, config, str(Path(work, tag)), data_dir=data)


def _breakdown(task: SampleTask) -> dict[str, Any]:
    """Render the sample as its build does and report Mitsuba seconds by pass group."""
    scene = _task_scene(task)
    calls: list[int] = []
    result = render_batches(
        scene, task.config.render, seed=task.seed, progress=calls.append, data_dir=task.data_dir
    )
    per_batch = count_passes(scene, task.config.render, data_dir=task.data_dir)
    timings = result.meta["timings"]
    return {
        "traversals_per_sample": len(calls),
        "traversals_per_batch_predicted": per_batch,
        "mitsuba_seconds_by_group": {k: round(v["seconds"], 3) for k, v in timings.items()},
        "passes_by_group": {k: v["passes"] for k, v in timings.items()},
    }


def _bench(work: str) -> dict[str, Any]:
    for name in INTEGRATORS:  # warm-up: kernels compiled here, not timed
        build_sample(_task(work, f"warm-{name}", name))
    runs: dict[str, list[Any]] = {name: [] for name in INTEGRATORS}
    for r in range(REPEATS):
        for name in INTEGRATORS:
            runs[name].append(build_sample(_task(work, f"{name}-{r}", name)))
    cores = os.cpu_count() or 1
    out: dict[str, Any] = {}
    for name, outcomes in runs.items():
        seconds = min(o.seconds for o in outcomes)
        out[name] = {
            "seconds_per_sample": [round(o.seconds, 3) for o in outcomes],
            "render_seconds_per_sample": [round(o.render_seconds, 3) for o in outcomes],
            "mitsuba_seconds_per_sample": [round(o.mitsuba_seconds, 3) for o in outcomes],
            "samples_per_core_hour": round(3600.0 / (seconds * cores), 1),
            **_breakdown(_task(work, f"breakdown-{name}", name)),
        }
    p, s = out["passes"], out["single"]
    out["ratio_samples_per_core_hour_single_over_passes"] = round(
        s["samples_per_core_hour"] / p["samples_per_core_hour"], 3
    )
    out["ratio_mitsuba_seconds_passes_over_single"] = round(
        min(p["mitsuba_seconds_per_sample"]) / min(s["mitsuba_seconds_per_sample"]), 3
    )
    out["ratio_traversals_passes_over_single"] = round(
        p["traversals_per_sample"] / s["traversals_per_sample"], 3
    )
    return out


def run(out_dir: Path) -> dict[str, Any]:
    """Samples per core-hour of :data:`SAMPLE` at the :data:`PRESET` preset, passes vs single.

    Returns
    -------
    dict
        Per integrator: seconds and Mitsuba seconds of each timed build, samples per core-hour
        (``3600 / (best seconds x cores)``, one process rendering on every core), traversals
        per sample and Mitsuba seconds by pass group; the ratios; the load average.
    """
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    results: dict[str, Any] = {
        "sample": SAMPLE,
        "preset": PRESET,
        "cpu_count": os.cpu_count(),
        "load_average_start": list(os.getloadavg()),
    }
    spawn = multiprocessing.get_context("spawn")
    with (
        tempfile.TemporaryDirectory(prefix="bench-traversal-") as tmp,
        ProcessPoolExecutor(max_workers=1, mp_context=spawn) as pool,
    ):
        results.update(pool.submit(_bench, tmp).result())
    results["load_average_end"] = list(os.getloadavg())
    return results
