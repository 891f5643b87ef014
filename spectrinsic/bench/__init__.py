"""``make bench``: run every benchmark module and write its results as JSON.

Each ``spectrinsic.bench.<name>`` module exposes ``run(out_dir) -> dict``; its results are
written to ``bench_<name>.json``. Results are ratios
measured within one run where possible, so they compare across machines.
"""

from __future__ import annotations

import argparse
import importlib
import json
import time
from pathlib import Path

from ..results import write_json

BENCHMARKS = (
    "render",
    "dataset",
    "traversal",
    "decompose",
    "ground_truth",
    "crop_reference",
    "relight",
    "residual",
    "storage",
    "real_scene",
    "artist_interior",
)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m spectrinsic.bench")
    parser.add_argument("--out", default="results/bench", help="folder for the JSON results")
    parser.add_argument("--only", nargs="*", choices=BENCHMARKS, help="run only these")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    summary = {}
    for name in args.only or BENCHMARKS:
        start = time.perf_counter()
        result = importlib.import_module(f"spectrinsic.bench.{name}").run(out)
        result["wall_seconds"] = time.perf_counter() - start
        write_json(out / f"bench_{name}.json", result, strict=False, default=str, end="")
        summary[f"bench_{name}"] = result
        print(f"bench_{name}: {json.dumps(result, default=str)[:2000]}")
    write_json(out / "summary.json", summary, strict=False, default=str, end="")
    return 0
