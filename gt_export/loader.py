"""Reading samples back: numpy arrays plus metadata, and an optional PyTorch ``Dataset``."""

from __future__ import annotations

import json
import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from spectrinsic.errors import DatasetError, MissingDependencyError
from spectrinsic.gt_export.exr import read_exr
from spectrinsic.gt_export.writer import META_NAME, sample_dirs

__all__ = ["load_sample", "load_dataset", "torch_dataset"]

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


def torch_dataset(
    dataset_dir: str | os.PathLike[str],
    *,
    keys: Sequence[str] = ("image", "reflectance", "shading", "mask"),
) -> Any:
    """A map-style ``torch.utils.data.Dataset`` over a dataset folder.

    Each item is ``{key: tensor}`` with images as ``(C, H, W)`` float32 and masks as ``(H, W)``
    bool, plus ``"sample_id"``. torch is imported only here.

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

    folders = sample_dirs(dataset_dir)
    wanted = [k for k in keys if k != "ids"]

    class SpectrinsicDataset(Dataset):  # type: ignore[misc, valid-type]
        def __len__(self) -> int:
            return len(folders)

        def __getitem__(self, index: int) -> dict[str, Any]:
            sample = load_sample(folders[index], layers=wanted)
            item: dict[str, Any] = {"sample_id": folders[index].name}
            for key in wanted:
                value = np.ascontiguousarray(sample[key])
                if value.ndim == 3:
                    value = np.ascontiguousarray(value.transpose(2, 0, 1))
                item[key] = torch.from_numpy(value)
            return item

    return SpectrinsicDataset()
