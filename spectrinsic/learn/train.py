"""Training the U-Net on a built dataset, with checkpoints and an exact resume.

Determinism on CPU: one thread (``torch.set_num_threads(1)``, so no reduction depends on the
thread count), ``torch.use_deterministic_algorithms(True)``, the weights initialised from
``torch.manual_seed(seed)`` and each step's batch from ``(seed, step)`` alone
(:func:`spectrinsic.learn.data.draw_batch`). A checkpoint holds the weights, the Adam state and
the curve, so a run resumed from step k computes the same steps k+1.. as an uninterrupted one
(checked by ``tests/learn/test_train.py``).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from ..errors import DatasetError
from ..file_writes import replacing
from ..gt_export.relight.augment import RandomRelight
from .data import TrainLayers, draw_batch, load_items, training_folders
from .loss import scale_invariant_loss
from .torch_import import require_torch
from .unet import UNetConfig, make_unet

__all__ = ["TrainOptions", "TrainResult", "CHECKPOINT", "train"]

#: The checkpoint file inside the output folder (replaced atomically at each save).
CHECKPOINT = "checkpoint.pt"

#: Called after each step with ``(step, loss)``.
StepCallback = Callable[[int, float], None]


@dataclass(frozen=True)
class TrainOptions:
    """Everything a training run depends on (recorded in the model card and the checkpoint).

    Attributes
    ----------
    steps
        Optimiser steps in all (a resumed run continues to this count).
    seed
        Root seed of the weights and of every batch.
    batch, crop
        Items per step, and the side of their random square crops in pixels (rounded down to a
        multiple of ``2 ** net.levels`` and to the samples' size).
    lr
        Adam's learning rate.
    layers
        The input image and targets (:class:`~spectrinsic.learn.data.TrainLayers`).
    samples
        Glob patterns of the sample ids trained on (``None``: every sample of the split).
    split
        The split trained on (splits go by scene).
    relight
        Relight each drawn item under random spectra (:class:`RandomRelight` seeded by
        *seed*); needs samples built with ``--store-transport``.
    checkpoint_every
        Steps between checkpoints.
    device
        ``"cpu"`` or ``"cuda"`` (deterministic on CPU only).
    net
        The U-Net's shape.
    """

    steps: int = 2000
    seed: int = 0
    batch: int = 8
    crop: int = 64
    lr: float = 1e-3
    layers: TrainLayers = field(default_factory=TrainLayers)
    samples: tuple[str, ...] | None = None
    split: str = "train"
    relight: bool = False
    checkpoint_every: int = 100
    device: str = "cpu"
    net: UNetConfig = field(default_factory=UNetConfig)

    def to_dict(self) -> dict[str, Any]:
        record = asdict(self)
        record["samples"] = None if self.samples is None else list(self.samples)
        return record


@dataclass(frozen=True)
class TrainResult:
    """What a run produced: the final state, the curve ``[(step, loss)]``, the samples trained
    on, the seconds spent (this run only) and the step it resumed from (0: a fresh run)."""

    state_dict: dict[str, Any]
    curve: list[tuple[int, float]]
    folders: list[Path]
    seconds: float
    resumed_from: int


def _deterministic(torch: Any, options: TrainOptions) -> None:
    if options.device == "cuda" and not torch.cuda.is_available():
        raise DatasetError("--device cuda: this torch sees no CUDA device; use --device cpu")
    torch.set_num_threads(1)
    torch.use_deterministic_algorithms(True, warn_only=options.device == "cuda")
    torch.manual_seed(options.seed)


def _crop(options: TrainOptions, shape: tuple[int, ...]) -> int:
    unit = 2**options.net.levels
    side = min(options.crop, shape[-2], shape[-1]) // unit * unit
    if side < unit:
        raise DatasetError(
            f"samples of {shape[-2]}x{shape[-1]} pixels are smaller than the U-Net's "
            f"{unit}-pixel unit; build larger samples or use fewer levels"
        )
    return side


def _save(torch: Any, path: Path, record: dict[str, Any]) -> None:
    with replacing(path) as tmp:  # a killed run leaves the previous checkpoint whole
        torch.save(record, tmp)


def _load_checkpoint(torch: Any, out: Path, options: TrainOptions) -> dict[str, Any]:
    path = out / CHECKPOINT
    if not path.is_file():
        raise DatasetError(f"--resume: {path} does not exist; start without --resume")
    record: dict[str, Any] = torch.load(path, map_location=options.device, weights_only=False)
    saved = dict(record["options"], steps=options.steps)
    if saved != options.to_dict():
        changed = sorted(k for k in saved if saved[k] != options.to_dict().get(k))
        raise DatasetError(f"--resume: {path} was trained with other options ({changed})")
    return record


def train(
    dataset: str | os.PathLike[str],
    out: Path,
    options: TrainOptions,
    *,
    resume: bool = False,
    on_step: StepCallback | None = None,
) -> TrainResult:
    """Train the U-Net on *dataset*'s split, checkpointing into *out* (which must exist).

    Raises
    ------
    DatasetError
        A set without the needed layers, an unusable device, or a checkpoint of other options.
    MissingDependencyError
        torch is not installed.
    """
    torch = require_torch("spectrinsic train")
    folders = training_folders(
        dataset, options.split, options.samples, options.layers, relight=options.relight
    )
    _deterministic(torch, options)
    items = load_items(folders, options.layers)
    crop = _crop(options, items[0].x.shape)
    model = make_unet(options.net).to(options.device)
    optimiser = torch.optim.Adam(model.parameters(), lr=options.lr)
    curve: list[tuple[int, float]] = []
    start = 0
    if resume:
        record = _load_checkpoint(torch, out, options)
        model.load_state_dict(record["state_dict"])
        optimiser.load_state_dict(record["optimiser"])
        curve, start = [tuple(p) for p in record["curve"]], int(record["step"])  # type: ignore[misc]
    relight = (
        (RandomRelight(seed=options.seed), folders, options.layers) if options.relight else None
    )
    began = time.perf_counter()
    for step in range(start + 1, options.steps + 1):
        arrays = draw_batch(
            items, step=step, seed=options.seed, batch=options.batch, crop=crop, relight=relight
        )
        x, r, s, m = (torch.from_numpy(a).to(options.device) for a in arrays)
        pred = model(x)
        loss = scale_invariant_loss(pred[:, :3], r, m) + scale_invariant_loss(pred[:, 3:], s, m)
        optimiser.zero_grad(set_to_none=True)
        loss.backward()
        optimiser.step()
        curve.append((step, float(loss.detach().cpu())))
        if on_step is not None:
            on_step(step, curve[-1][1])
        if step % options.checkpoint_every == 0 or step == options.steps:
            _save(
                torch,
                out / CHECKPOINT,
                {
                    "state_dict": model.state_dict(),
                    "optimiser": optimiser.state_dict(),
                    "step": step,
                    "curve": curve,
                    "options": options.to_dict(),
                },
            )
    state = {k: v.detach().cpu() for k, v in model.state_dict().items()}
    return TrainResult(state, curve, folders, time.perf_counter() - began, start)
