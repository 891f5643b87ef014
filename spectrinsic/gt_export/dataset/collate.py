"""Batching samples: per-light layers padded to one light count, with a light mask.

Every layer of a dataset has the same size in every sample, except the per-light ones
(:data:`PER_LIGHT_LAYERS`): ``light_share`` has one channel per light, and samples have 1 to 4
lights. PyTorch's default collate stacks each key and so fails on them ("stack expects each
tensor to be equal size"). :func:`collate` pads them with zeros to *max_lights* channels and adds
``light_mask``, ``(B, max_lights)`` bool, true for the channels of real lights. Channel *i*
stays ``meta["lights"][i]``; a padded channel is 0 everywhere, so the shares of each pixel still
sum to 1 over the real lights (or to 0 where no surface is seen).

It takes the items of both loaders: :func:`~spectrinsic.gt_export.torch_dataset` items
(channel-first tensors, a one-light share ``(1, H, W)``) and
:func:`~spectrinsic.gt_export.dataset.shards.shard_dataset` items (channel-last arrays as
:func:`~spectrinsic.gt_export.load_sample` returns them, a one-light share ``(H, W)``)::

    loader = DataLoader(torch_dataset("data/rooms", crop=(128, 128), seed=0),
                        batch_size=8, collate_fn=collate)

Arrays are stacked along a new first axis, dictionaries of arrays (``ids``) collated key by
key, numbers become a ``(B,)`` array, and everything else (``sample_id``, ``scene``, ``meta``)
a list of *B* values. :func:`collate_arrays` is the same in numpy alone.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from numbers import Number
from typing import Any

import numpy as np

from ...errors import DatasetError

__all__ = ["PER_LIGHT_LAYERS", "LIGHT_MASK", "pad_lights", "collate_arrays", "collate"]

#: Layers with one channel per light of the sample (group ``"lights"`` in ``meta.json``).
PER_LIGHT_LAYERS: tuple[str, ...] = ("light_share",)
#: Key of the added ``(B, max_lights)`` bool mask of real light channels.
LIGHT_MASK = "light_mask"


def pad_lights(share: np.ndarray, max_lights: int, *, channel_first: bool) -> np.ndarray:
    """A per-light layer zero-padded to *max_lights* channels.

    Parameters
    ----------
    share
        ``(L, H, W)`` (*channel_first*) or ``(H, W, L)``; a 2-D ``(H, W)`` array is one light.
    max_lights
        Channels of the result, ``>= L``.

    Returns
    -------
    numpy.ndarray
        ``(max_lights, H, W)`` or ``(H, W, max_lights)``, *share*'s dtype; channels ``>= L``
        are 0.
    """
    axis = 0 if channel_first else -1
    share = np.asarray(share)
    if share.ndim == 2:
        share = np.expand_dims(share, axis)
    n = share.shape[axis]
    if n > max_lights:
        raise DatasetError(f"a sample has {n} lights; expected at most max_lights={max_lights}")
    widths = [(0, 0)] * share.ndim
    widths[axis] = (0, max_lights - n)
    return np.pad(share, widths)


def _n_lights(share: np.ndarray, channel_first: bool) -> int:
    return 1 if share.ndim == 2 else int(share.shape[0 if channel_first else -1])


def _is_array_dict(value: Any) -> bool:
    return (
        isinstance(value, Mapping)
        and bool(value)
        and all(isinstance(v, np.ndarray) for v in value.values())
    )


def _stack(key: str, values: Sequence[np.ndarray]) -> np.ndarray:
    shapes = {v.shape for v in values}
    if len(shapes) > 1:
        raise DatasetError(
            f"cannot batch layer {key!r}: its shapes differ between samples "
            f"({', '.join(map(str, sorted(shapes)))}); crop every sample to one size "
            "(torch_dataset(..., crop=(H, W), seed=...))"
        )
    return np.stack(values)


def _collate_key(key: str, values: list[Any]) -> Any:
    first = values[0]
    if isinstance(first, np.ndarray):
        return _stack(key, values)
    if _is_array_dict(first):
        return {k: _collate_key(f"{key}.{k}", [v[k] for v in values]) for k in first}
    if isinstance(first, Number) and not isinstance(first, bool):
        return np.asarray(values)
    return list(values)


def collate_arrays(
    items: Sequence[Mapping[str, Any]],
    *,
    max_lights: int | None = None,
    channel_first: bool | None = None,
) -> dict[str, Any]:
    """Collate numpy items into one batch (see the module docstring).

    Parameters
    ----------
    items
        Items of one loader, all with the same keys.
    max_lights
        Channels of every per-light layer; ``None``: the most lights of a sample in *items*
        (fix it, e.g. 4, for one size in every batch).
    channel_first
        Layout of the items' layers; ``None``: channel-first for items made by
        :func:`~spectrinsic.gt_export.dataset.loader.prepare_item` (``torch_dataset``; they carry
        ``exposure_scale``), else channel-last (``load_sample`` and ``shard_dataset`` items).

    Returns
    -------
    dict
        Arrays ``(B, ...)``; ``light_mask`` ``(B, max_lights)`` bool where a per-light layer is
        present; lists for the other values.
    """
    if not items:
        raise DatasetError("cannot collate an empty batch")
    keys = list(items[0])
    missing = sorted({k for item in items for k in keys if k not in item})
    if missing:
        raise DatasetError(f"cannot batch: some samples lack the keys {missing}")
    if channel_first is None:  # prepare_item (torch_dataset) marks its items by their exposure
        channel_first = "exposure_scale" in items[0]
    per_light = [k for k in PER_LIGHT_LAYERS if k in items[0]]
    batch: dict[str, Any] = {}
    if per_light:
        counts = np.array(
            [_n_lights(np.asarray(item[per_light[0]]), channel_first) for item in items]
        )
        width = int(counts.max()) if max_lights is None else int(max_lights)
        for key in per_light:
            batch[key] = _stack(
                key, [pad_lights(item[key], width, channel_first=channel_first) for item in items]
            )
        batch[LIGHT_MASK] = np.arange(width)[None, :] < counts[:, None]
    for key in keys:
        if key not in batch:
            batch[key] = _collate_key(key, [item[key] for item in items])
    return batch


def _to_numpy(value: Any) -> Any:
    if hasattr(value, "detach") and hasattr(value, "numpy"):  # a torch tensor
        return value.detach().cpu().numpy()
    if _is_tensor_dict(value):
        return {k: _to_numpy(v) for k, v in value.items()}
    return value


def _is_tensor_dict(value: Any) -> bool:
    return (
        isinstance(value, Mapping)
        and bool(value)
        and all(hasattr(v, "detach") for v in value.values())
    )


def _to_torch(value: Any, torch: Any) -> Any:
    if isinstance(value, np.ndarray):
        return torch.from_numpy(value)
    return {k: _to_torch(v, torch) for k, v in value.items()} if _is_array_dict(value) else value


def collate(items: Sequence[Mapping[str, Any]], *, max_lights: int | None = None) -> dict[str, Any]:
    """``collate_fn`` for a ``torch.utils.data.DataLoader`` over either loader: as
    :func:`collate_arrays`, with every array returned as a tensor (needs torch). Use
    ``functools.partial(collate, max_lights=4)`` for one light count in every batch."""
    import torch

    arrays = [{k: _to_numpy(v) for k, v in item.items()} for item in items]
    batch = collate_arrays(arrays, max_lights=max_lights)
    return {k: _to_torch(v, torch) for k, v in batch.items()}
