"""The training data: the samples of a split held in memory as log arrays, and each step's
batch of random crops and flips drawn from the step's own seed.

A step's batch depends only on ``(seed, step)`` (``default_rng([seed, step])``), never on what
ran before it, so a resumed run draws exactly the batches of an uninterrupted one.
"""

from __future__ import annotations

import fnmatch
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DatasetError
from ..gt_export.dataset.loader import load_sample, split_samples
from ..gt_export.relight.augment import RandomRelight
from ..gt_export.sample.meta import read_meta
from ..gt_export.sample.working_view import srgb_view
from .logspace import log_input, log_layer

__all__ = ["TrainLayers", "LogItem", "training_folders", "log_item", "load_items", "draw_batch"]


@dataclass(frozen=True)
class TrainLayers:
    """Which sample layers the network learns from: the input image and its two targets.

    The default is the reference image and its ground truth; ``image_rgb3`` trains on the
    3-sensor render of the same scenes (same targets), and a camera's
    ``image_sensor_noisy/<camera>`` with ``reflectance_sensor/<camera>`` and
    ``shading_sensor/<camera>`` on the camera chain's processed image.
    """

    image: str = "image"
    reflectance: str = "reflectance"
    shading: str = "shading"

    def keys(self) -> tuple[str, ...]:
        return (self.image, self.reflectance, self.shading, "mask")


@dataclass(frozen=True)
class LogItem:
    """One sample in log space, channel first: ``x`` the input (3, H, W), ``r`` and ``s`` the
    log reflectance and shading (3, H, W), ``m`` the mask (1, H, W) bool; all float32 but ``m``."""

    x: np.ndarray
    r: np.ndarray
    s: np.ndarray
    m: np.ndarray


def training_folders(
    dataset: str | os.PathLike[str],
    split: str,
    patterns: Sequence[str] | None,
    layers: TrainLayers,
    *,
    relight: bool = False,
) -> list[Path]:
    """The sample folders of *split* whose id matches one of *patterns* (all when None), each
    checked to hold the layers of *layers* (and, with *relight*, its stored transport).

    Raises
    ------
    DatasetError
        No sample selected, or a sample without a needed layer or transport (one line naming
        both).
    """
    folders = split_samples(dataset, split)
    if patterns:
        folders = [f for f in folders if any(fnmatch.fnmatchcase(f.name, p) for p in patterns)]
    if not folders:
        raise DatasetError(
            f"{dataset}: no sample of split {split!r} matches {list(patterns or ['*'])}"
        )
    for folder in folders:
        meta = read_meta(folder)
        if relight and meta.transport is None:
            raise DatasetError(
                f"{folder}: --relight needs each sample's light transport; build the set with "
                "--store-transport"
            )
        missing = [k for k in layers.keys() if k not in meta.layers]
        if missing:
            raise DatasetError(
                f"{folder}: training needs the layers {list(layers.keys())}; this sample "
                f"has no {missing[0]!r}"
            )
    return folders


def log_item(sample: dict[str, Any], layers: TrainLayers) -> LogItem:
    """A loaded sample (arrays ``(H, W, C)``, linear sRGB view) as a :class:`LogItem`."""
    mask = np.asarray(sample["mask"], bool)
    chw = np.ascontiguousarray
    return LogItem(
        x=chw(np.moveaxis(log_input(sample[layers.image], mask), -1, 0)),
        r=chw(np.moveaxis(log_layer(sample[layers.reflectance]), -1, 0)),
        s=chw(np.moveaxis(log_layer(sample[layers.shading]), -1, 0)),
        m=mask[None],
    )


def load_items(folders: Sequence[Path], layers: TrainLayers) -> list[LogItem]:
    """Every folder's sample in log space, in the linear sRGB view the evaluation scores."""
    return [log_item(load_sample(f, layers=layers.keys(), space="srgb"), layers) for f in folders]


def _relit_item(
    folder: Path, index: int, step: int, relight: RandomRelight, layers: TrainLayers
) -> LogItem:
    relit = relight(folder, index, step)
    return log_item(srgb_view(relit, relit["meta"]), layers)


def draw_batch(
    items: Sequence[LogItem],
    *,
    step: int,
    seed: int,
    batch: int,
    crop: int,
    relight: tuple[RandomRelight, Sequence[Path], TrainLayers] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The batch of *step*: ``x, r, s, m`` stacked ``(batch, C, crop, crop)``.

    Items are drawn with replacement; each gets a random ``crop`` x ``crop`` window (the whole
    side when the sample is smaller; *crop* a multiple of the U-Net's ``2 ** levels``) and a
    horizontal flip with probability 1/2. With *relight* (the :class:`RandomRelight`, the
    folders and layers), a drawn item is relit under the spectra of ``(index, step)`` first.
    """
    rng = np.random.default_rng([int(seed), int(step)])
    picks = rng.integers(len(items), size=batch)
    out: list[list[np.ndarray]] = [[], [], [], []]
    for index in picks:
        item = items[index]
        if relight is not None:
            item = _relit_item(relight[1][index], int(index), step, relight[0], relight[2])
        h, w = item.x.shape[1:]
        ch, cw = min(crop, h), min(crop, w)
        y0, x0 = int(rng.integers(h - ch + 1)), int(rng.integers(w - cw + 1))
        flip = bool(rng.integers(2))
        for slot, arr in zip(out, (item.x, item.r, item.s, item.m), strict=True):
            window = arr[:, y0 : y0 + ch, x0 : x0 + cw]
            slot.append(window[:, :, ::-1] if flip else window)
    x, r, s, m = (np.ascontiguousarray(np.stack(a)) for a in out)
    return x, r, s, m
