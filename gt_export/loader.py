"""Reading samples back: numpy arrays plus metadata, and an optional PyTorch ``Dataset``."""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from spectrinsic.errors import DatasetError, MissingDependencyError
from spectrinsic.gt_export.exr import read_exr
from spectrinsic.gt_export.writer import META_NAME, sample_dirs

__all__ = ["load_sample", "load_dataset", "split_samples", "prepare_item", "torch_dataset"]

_INT_LAYERS = ("material_id", "object_id")


def load_sample(
    path: str | os.PathLike[str], *, layers: Sequence[str] | None = None
) -> dict[str, Any]:
    """Load one sample folder written by :func:`spectrinsic.gt_export.export_sample`.

    Parameters
    ----------
    path
        The sample folder.
    layers
        Only these layer keys (default: all that ``meta.json`` lists).

    Returns
    -------
    dict
        ``image``, ``reflectance``, ``shading``, ``illuminant`` (``(H, W, 3)`` float32 linear
        sRGB), ``shading_grey``, ``depth`` (``(H, W)`` float32), ``normals`` (``(H, W, 3)``),
        ``mask`` (``(H, W)`` bool), ``ids`` (``{"material": (H, W) int32, "object": ...}``, -1
        background), per-camera keys ``image_camera/<name>`` etc., ``cube`` when written, and
        ``meta`` (the parsed ``meta.json``). Units are in ``meta["layers"][key]["units"]``.
    """
    path = Path(path)
    try:
        meta = json.loads((path / META_NAME).read_text(encoding="utf-8"))
    except OSError as exc:
        raise DatasetError(f"sample folder {str(path)!r} has no readable {META_NAME}") from exc
    except ValueError as exc:
        raise DatasetError(f"{path / META_NAME}: not valid JSON ({exc})") from exc
    records = meta.get("layers", {})
    wanted = list(records) if layers is None else list(layers)
    unknown = [k for k in wanted if k not in records]
    if unknown:
        raise DatasetError(f"sample {path.name!r} has no layers {unknown}; it has {sorted(records)}")
    by_file: dict[str, list[str]] = {}
    for key in wanted:
        by_file.setdefault(records[key]["file"], []).append(key)
    out: dict[str, Any] = {}
    for file, keys in by_file.items():
        arrays = read_exr(path / file, layers=[records[k]["exr_layer"] for k in keys])
        for key in keys:
            out[key] = arrays[records[key]["exr_layer"]]
    if "mask" in out:
        out["mask"] = out["mask"] > 0.5
    ids = {}
    for key in _INT_LAYERS:
        if key in out:
            out[key] = np.rint(out[key]).astype(np.int32)
            ids[key.removesuffix("_id")] = out[key]
    if ids:
        out["ids"] = ids
    out["meta"] = meta
    return out


def load_dataset(
    dataset_dir: str | os.PathLike[str], *, layers: Sequence[str] | None = None
) -> Iterator[dict[str, Any]]:
    """Iterate :func:`load_sample` over the complete samples of *dataset_dir*, sorted by id."""
    for sample in sample_dirs(dataset_dir):
        yield load_sample(sample, layers=layers)


#: Layers in radiometric units that exposure normalisation scales (reflectance is unitless).
EXPOSED_PREFIXES = ("image", "shading", "illuminant", "residual", "cube")
#: Luminance percentile mapped to 1 by exposure normalisation.
EXPOSURE_PERCENTILE = 99.0


def split_samples(dataset_dir: str | os.PathLike[str], split: str | None) -> list[Path]:
    """Sample folders of *split* (``"train"``, ``"val"``, ``"test"``; ``None``: all) from the
    manifest's ``splits`` (made by scene, so no scene is in two splits)."""
    folders = sample_dirs(dataset_dir)
    if split is None:
        return folders
    try:
        splits = json.loads((Path(dataset_dir) / "manifest.json").read_text(encoding="utf-8"))["splits"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise DatasetError(f"{dataset_dir}: manifest.json has no splits; rebuild the dataset") from exc
    if split not in splits:
        raise DatasetError(f"split {split!r}; expected one of {sorted(splits)}")
    chosen = set(splits[split])
    return [f for f in folders if f.name in chosen]


def _channel_first(value: np.ndarray) -> np.ndarray:
    """``(H, W)`` -> ``(1, H, W)``; ``(H, W, C)`` -> ``(C, H, W)``."""
    value = value[..., None] if value.ndim == 2 else value
    return np.ascontiguousarray(np.moveaxis(value, -1, 0))


def prepare_item(
    sample: dict[str, Any],
    *,
    crop: tuple[int, int] | None = None,
    rng: np.random.Generator | None = None,
    normalize_exposure: bool = False,
) -> dict[str, Any]:
    """A loaded sample as channel-first arrays: every layer ``(C, H, W)`` (depth and masks get
    ``C = 1``), ``ids`` as ``{"material"|"object": (1, H, W) int32}``, ``sample_id``,
    ``scene`` and ``exposure_scale``.

    Parameters
    ----------
    crop
        ``(height, width)`` of one random crop shared by all layers (needs *rng*).
    rng
        Generator of the crop position (explicit: no hidden global state).
    normalize_exposure
        Scale the radiometric layers (:data:`EXPOSED_PREFIXES`) so the image's
        :data:`EXPOSURE_PERCENTILE`-th luminance percentile is 1 (image = reflectance x shading
        + residual still holds, each side scaled alike).
    """
    arrays = {k: v for k, v in sample.items() if isinstance(v, np.ndarray)}
    scale = 1.0
    if normalize_exposure and "image" in arrays:
        y = arrays["image"] @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
        scale = 1.0 / max(float(np.percentile(y, EXPOSURE_PERCENTILE)), 1e-12)
    if crop is not None:
        if rng is None:
            raise DatasetError("a random crop needs an explicit numpy Generator (rng=...)")
        h, w = next(iter(arrays.values())).shape[:2]
        if crop[0] > h or crop[1] > w:
            raise DatasetError(f"crop {crop} is larger than the {h}x{w} sample")
        y0, x0 = int(rng.integers(h - crop[0] + 1)), int(rng.integers(w - crop[1] + 1))
        arrays = {k: v[y0:y0 + crop[0], x0:x0 + crop[1]] for k, v in arrays.items()}
    item: dict[str, Any] = {}
    for key, value in arrays.items():
        if normalize_exposure and key.startswith(EXPOSED_PREFIXES):
            value = (value * np.float32(scale)).astype(value.dtype)
        item[key] = _channel_first(value)
    item["ids"] = {k.removesuffix("_id"): item[k] for k in _INT_LAYERS if k in item}
    meta = sample.get("meta", {})
    item.update(sample_id=meta.get("sample_id"), scene=meta.get("scene"), exposure_scale=scale)
    return item


def torch_dataset(
    dataset_dir: str | os.PathLike[str],
    *,
    keys: Sequence[str] | None = None,
    split: str | None = None,
    crop: tuple[int, int] | None = None,
    seed: int | None = None,
    normalize_exposure: bool = False,
    transform: Any = None,
    relight: Callable[[Path, int, int], dict[str, Any]] | None = None,
) -> Any:
    """A map-style ``torch.utils.data.Dataset`` over a dataset folder.

    Each item is :func:`prepare_item` with arrays as tensors: every layer (``keys=None``) or
    the chosen ones, ``ids`` (a dict of int tensors), the cube when written, ``sample_id`` and
    ``scene``; images ``(C, H, W)`` float32, masks ``(1, H, W)`` bool. *transform*, if given,
    is applied to each item dict. *relight* (a :class:`~spectrinsic.gt_export.relight_pool.RandomRelight`)
    replaces each sample by itself relit under random light spectra (samples built with
    ``--store-transport``). Random crops need *seed*: item *i* is cropped with
    ``default_rng([seed, i])``, the same on every worker and epoch. torch is imported only here.

    Raises
    ------
    MissingDependencyError
        If torch is not installed (``pip install 'spectrinsic[torch]'``).
    """
    try:
        import torch
        from torch.utils.data import Dataset
    except ImportError as exc:
        raise MissingDependencyError(
            "torch_dataset needs PyTorch, which is not installed: pip install 'spectrinsic[torch]'"
        ) from exc
    if crop is not None and seed is None:
        raise DatasetError("torch_dataset: a random crop needs an explicit seed")
    folders = split_samples(dataset_dir, split)
    wanted = None if keys is None else [k for k in keys if k != "ids"]

    def tensors(value: Any) -> Any:
        if isinstance(value, np.ndarray):
            return torch.from_numpy(value)
        return {k: tensors(v) for k, v in value.items()} if isinstance(value, dict) else value

    class SpectrinsicDataset(Dataset):  # type: ignore[misc, valid-type]
        #: Epoch passed to *relight* (``set_epoch`` before each epoch draws new spectra).
        epoch = 0

        def set_epoch(self, epoch: int) -> None:
            self.epoch = int(epoch)

        def __len__(self) -> int:
            return len(folders)

        def __getitem__(self, index: int) -> dict[str, Any]:
            if relight is None:
                sample = load_sample(folders[index], layers=wanted)
            else:
                relit = relight(folders[index], index, self.epoch)
                sample = {k: v for k, v in relit.items() if wanted is None or k in wanted or k == "meta"}
            rng = None if seed is None else np.random.default_rng([seed, index])
            item = tensors(prepare_item(sample, crop=crop, rng=rng,
                                        normalize_exposure=normalize_exposure))
            return transform(item) if transform is not None else item

    return SpectrinsicDataset()
