"""What a training run writes: the weights, the curve (CSV and PNG) and the model card
(``MODEL.md`` and ``model.json``: the data, its config hash and sample count, the options, the
time and the software)."""

from __future__ import annotations

import csv
import io
import json
import os
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..file_writes import replacing, write_text_file
from ..gt_export.sample.meta import read_meta
from ..provenance import provenance
from .torch_import import require_torch
from .train import TrainOptions, TrainResult
from .unet import FORMAT

__all__ = ["WEIGHTS", "CURVE_CSV", "CURVE_PNG", "CARD_MD", "CARD_JSON", "FORMAT", "write_outputs"]

WEIGHTS = "weights.pt"
CURVE_CSV = "curve.csv"
CURVE_PNG = "curve.png"
CARD_MD = "MODEL.md"
CARD_JSON = "model.json"


def _config_hashes(folders: Sequence[Path]) -> list[str]:
    return sorted({read_meta(f).config_hash for f in folders})


def card_record(
    dataset: str | os.PathLike[str], options: TrainOptions, result: TrainResult
) -> dict[str, Any]:
    """The model card's JSON record."""
    torch = require_torch("the model card")
    return {
        "format": FORMAT,
        "dataset": Path(dataset).resolve().name,  # its folder's name: no absolute path written
        "config_hashes": _config_hashes(result.folders),
        "samples": len(result.folders),
        "sample_ids": [f.name for f in result.folders],
        "options": options.to_dict(),
        "steps_this_run": options.steps - result.resumed_from,
        "resumed_from": result.resumed_from,
        "seconds_this_run": round(result.seconds, 2),
        "final_loss": result.curve[-1][1] if result.curve else None,
        "written": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "torch": str(torch.__version__),
        **provenance(),
    }


def _curve_png(path: Path, curve: Sequence[tuple[int, float]]) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5, 3))
    ax = fig.add_subplot()
    ax.plot([c[0] for c in curve], [c[1] for c in curve], lw=0.8)
    ax.set(xlabel="step", ylabel="loss (scale-invariant, R + S)", yscale="log")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=120)


def _card_md(record: dict[str, Any]) -> str:
    opts = record["options"]
    lines = [
        "# Model card: spectrinsic U-Net",
        "",
        "A small U-Net predicting log reflectance and log shading from the log image, trained",
        "with the scale-invariant loss of Eigen et al. 2014 (spectrinsic.learn.loss).",
        "",
        f"- data: `{record['dataset']}`, {record['samples']} samples of split "
        f"`{opts['split']}`, config hash(es) {', '.join(record['config_hashes'])}",
        f"- layers: input `{opts['layers']['image']}`, targets `{opts['layers']['reflectance']}`"
        f" and `{opts['layers']['shading']}`",
        f"- steps {opts['steps']} (this run {record['steps_this_run']}, resumed from "
        f"{record['resumed_from']}), batch {opts['batch']}, crop {opts['crop']}, lr {opts['lr']},"
        f" seed {opts['seed']}, relight {opts['relight']}, device {opts['device']}",
        f"- network: {opts['net']}",
        f"- final loss {record['final_loss']}, {record['seconds_this_run']} s this run, "
        f"written {record['written']}, torch {record['torch']}, git {record['git_sha']}",
        "",
        f"Options in full: `{CARD_JSON}`; curve: `{CURVE_CSV}`, `{CURVE_PNG}`.",
    ]
    return "\n".join(lines) + "\n"


def write_outputs(
    out: Path, dataset: str | os.PathLike[str], options: TrainOptions, result: TrainResult
) -> dict[str, Path]:
    """Write the weights, curve and card into *out*; their paths by kind."""
    torch = require_torch("spectrinsic train")
    record = card_record(dataset, options, result)
    paths = {
        k: out / v
        for k, v in (
            ("weights", WEIGHTS),
            ("curve_csv", CURVE_CSV),
            ("curve_png", CURVE_PNG),
            ("card_md", CARD_MD),
            ("card_json", CARD_JSON),
        )
    }
    weights = {
        "format": FORMAT,
        "net": options.net.to_dict(),
        "layers": record["options"]["layers"],
        "state_dict": result.state_dict,
        "card": record,
    }
    with replacing(paths["weights"]) as tmp:
        torch.save(weights, tmp)
    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(["step", "loss"])
    writer.writerows((s, f"{v:.9g}") for s, v in result.curve)
    write_text_file(paths["curve_csv"], text.getvalue())
    _curve_png(paths["curve_png"], result.curve)
    write_text_file(paths["card_json"], json.dumps(record, indent=1) + "\n")
    write_text_file(paths["card_md"], _card_md(record))
    return paths
