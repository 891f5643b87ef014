"""Reading samples back: numpy arrays plus metadata, and an optional PyTorch ``Dataset``."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError, MissingDependencyError
from ..formats.exr import read_exr
from ..formats.png import EXPOSURE_PERCENTILE, exposure
from ..layers.spectral_intrinsics import bands_to_rgb, rgb_residual_share, working_space_matrix
from ..sample import META_NAME, file_sha256, sample_dirs
from ..sample.meta import SampleMeta, read_meta
from ..sample.working_view import space_of, srgb_view, view_kind
from .manifest import read_splits

__all__ = [
    "load_sample",
    "load_dataset",
    "split_samples",
    "prepare_item",
    "torch_dataset",
    "filter_residual_share",
    "working_space_view",
    "EXPOSURE_PERCENTILE",
]

_INT_LAYERS = ("material_id", "object_id", "semantic")


def _verified(meta: SampleMeta, file: str) -> Path:
    """The path of *file* of the sample after checking it against its SHA-256 in ``meta.json``."""
    path = meta.folder / file
    if not path.is_file():
        raise DatasetError(f"{path}: listed in {META_NAME} but missing; the sample is incomplete")
    if file_sha256(path) != meta.hashes.get(file):
        raise DatasetError(
            f"{path}: does not match its SHA-256 in {META_NAME}; the sample is "
            f"damaged (spectrinsic check finds every such file)"
        )
    return path


def load_sample(
    path: str | os.PathLike[str],
    *,
    layers: Sequence[str] | None = None,
    verify: bool = True,
    space: str | None = None,
) -> dict[str, Any]:
    """Load one sample folder written by :func:`spectrinsic.gt_export.export_sample`.

    Parameters
    ----------
    path
        The sample folder.
    layers
        Only these layer keys (default: all that ``meta.json`` lists).
    verify
        Check ``meta.json`` against its seal and every file read against its SHA-256 before
        decoding it (about as long again as reading; ``False`` trusts the files).
    space
        ``None`` (default): the RGB layers as stored, in the sample's working space
        (``meta["working_space"]``: ACEScg by default, linear sRGB for ``--working-space
        srgb`` and samples from before the working space was recorded); ``"srgb"``: their
        linear sRGB view (:mod:`~spectrinsic.gt_export.sample.working_view`; the residuals
        recomputed so the identities hold; shading not clipped).

    Returns
    -------
    dict
        ``image``, ``reflectance``, ``shading``, ``illuminant`` (``(H, W, 3)`` float32 linear
        RGB of the working space, or sRGB with ``space="srgb"``), ``shading_grey``, ``depth`` (``(H, W)`` float32), ``normals`` (``(H, W, 3)``),
        ``mask`` (``(H, W)`` bool), ``ids`` (``{"material": (H, W) int32, "object": ...,
        "semantic": ...}``, -1 background; ``semantic`` indexes ``meta["semantic_classes"]``),
        per-camera keys ``image_camera/<name>`` etc., ``cube`` when written, and
        ``meta`` (the parsed ``meta.json``). Units are in ``meta["layers"][key]["units"]``.

    Raises
    ------
    DatasetError
        A ``meta.json`` that is damaged (:class:`~spectrinsic.errors.SampleMetaError`, naming
        the field; layer files outside the sample folder are refused there), an unknown layer,
        or (with *verify*) a file that does not match its SHA-256.
    """
    _check_space(space)
    meta = read_meta(path, verify=verify)
    records = meta.layers
    wanted = list(records) if layers is None else list(layers)
    unknown = [k for k in wanted if k not in records]
    if unknown:
        raise DatasetError(
            f"sample {meta.sample_id!r} has no layers {unknown}; it has {sorted(records)}"
        )
    asked = wanted
    wanted = _with_identity_members(wanted, meta.raw, records) if space == "srgb" else wanted
    by_file: dict[str, list[str]] = {}
    for key in wanted:
        by_file.setdefault(records[key].file, []).append(key)
    out: dict[str, Any] = {}
    for file, keys in by_file.items():
        source = _verified(meta, file) if verify else meta.folder / file
        arrays = read_exr(source, layers=[records[k].exr_layer for k in keys])
        for key in keys:
            out[key] = arrays[records[key].exr_layer]
    if "mask" in out:
        out["mask"] = out["mask"] > 0.5
    ids = {}
    for key in _INT_LAYERS:
        if key in out:
            if out[key].dtype != np.int32:  # format 2 stored ids as float32
                out[key] = np.rint(out[key]).astype(np.int32)
            ids[key.removesuffix("_id")] = out[key]
    if ids:
        out["ids"] = ids
    out["meta"] = dict(meta.raw)
    if space == "srgb":
        out = srgb_view(out, out["meta"])
        out = {k: v for k, v in out.items() if k in asked or k in ("ids", "meta")}
    return out


def _check_space(space: str | None) -> None:
    if space not in (None, "srgb"):
        raise DatasetError(f"load_sample space={space!r}; expected None (as stored) or 'srgb'")


def _with_identity_members(wanted: list[str], meta: Any, records: Any) -> list[str]:
    """*wanted* plus what the sRGB view needs to recompute a wanted residual or ratio."""
    out = list(wanted)
    if space_of(meta).name == "srgb":
        return out
    identities = meta.get("identities")
    needs = [k for k in wanted if view_kind(k) == "recomputed"]
    for ident in identities if needs and isinstance(identities, list) else []:
        if isinstance(ident, Mapping) and (
            ident.get("residual") in needs or "shading_ratio" in needs
        ):
            out += [v for v in ident.values() if v in records and v not in out]
    return out


def load_dataset(
    dataset_dir: str | os.PathLike[str],
    *,
    layers: Sequence[str] | None = None,
    verify: bool = True,
    max_residual_share: float | None = None,
    space: str | None = None,
    split: str | None = None,
) -> Iterator[dict[str, Any]]:
    """Iterate :func:`load_sample` over the complete samples of *dataset_dir*, sorted by id;
    with *split* (``"train"``, ``"val"``, ``"test"``), only that split's, as ``torch_dataset``
    (:func:`split_samples`); with *max_residual_share*, only those whose RGB residual share
    is at most that (:func:`filter_residual_share`); *space* as :func:`load_sample`'s."""
    for sample in filter_residual_share(split_samples(dataset_dir, split), max_residual_share):
        yield load_sample(sample, layers=layers, verify=verify, space=space)


def filter_residual_share(folders: Sequence[Path], limit: float | None) -> list[Path]:
    """The sample *folders* whose RGB residual share (``meta.json["residual_share"]``,
    ``Σ|residual| / Σ|image|`` over the mask, a fraction) is at most *limit*; all for ``None``.
    Samples that record no share (written before it existed) are left out."""
    if limit is None:
        return list(folders)
    if not (isinstance(limit, (int, float)) and 0 <= limit):
        raise DatasetError(
            f"max_residual_share={limit!r}; expected a fraction >= 0 (e.g. 0.05 for 5 %)"
        )
    out = []
    for folder in folders:
        share = rgb_residual_share(read_meta(folder, verify=False).raw)
        if share is not None and share <= limit:
            out.append(folder)
    return out


#: Layers in radiometric units that exposure normalisation scales (reflectance is unitless).
EXPOSED_PREFIXES = ("image", "shading", "illuminant", "residual", "specular", "cube")


def split_samples(dataset_dir: str | os.PathLike[str], split: str | None) -> list[Path]:
    """Sample folders of *split* (``"train"``, ``"val"``, ``"test"``; ``None``: all) from the
    manifest's ``splits`` (made by scene, so no scene is in two splits).

    Raises
    ------
    DatasetError
        An unknown split, or an empty one (naming the split and the dataset's scene count).
    """
    folders = sample_dirs(dataset_dir)
    if split is None:
        return folders
    chosen = set(read_splits(dataset_dir, split)[split])
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
    ``C = 1``), ``ids`` as ``{"material"|"object"|"semantic": (1, H, W) int32}``, ``sample_id``,
    ``scene`` and ``exposure_scale``.

    Parameters
    ----------
    crop
        ``(height, width)`` of one random crop shared by all layers (needs *rng*).
    rng
        Generator of the crop position (explicit: no hidden global state).
    normalize_exposure
        Scale the radiometric layers (:data:`EXPOSED_PREFIXES`) by the previews' exposure
        (:func:`spectrinsic.gt_export.formats.png.exposure`: the :data:`EXPOSURE_PERCENTILE`-th
        percentile of the image's positive luminances maps to 1; background pixels do not
        count), so image = reflectance x shading + residual still holds, each side scaled alike.
    """
    arrays = {k: v for k, v in sample.items() if isinstance(v, np.ndarray)}
    scale = 1.0
    if normalize_exposure and "image" in arrays:
        # the previews' exposure, one definition: of the sRGB view's luminance
        scale = exposure(space_of(sample.get("meta")).srgb(arrays["image"]))
    if crop is not None:
        if rng is None:
            raise DatasetError("a random crop needs an explicit numpy Generator (rng=...)")
        h, w = next(iter(arrays.values())).shape[:2]
        if crop[0] > h or crop[1] > w:
            raise DatasetError(f"crop {crop} is larger than the {h}x{w} sample")
        y0, x0 = int(rng.integers(h - crop[0] + 1)), int(rng.integers(w - crop[1] + 1))
        arrays = {k: v[y0 : y0 + crop[0], x0 : x0 + crop[1]] for k, v in arrays.items()}
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
    verify: bool = True,
    crop: tuple[int, int] | None = None,
    seed: int | None = None,
    normalize_exposure: bool = False,
    transform: Any = None,
    relight: Callable[[Path, int, int], dict[str, Any]] | None = None,
    max_residual_share: float | None = None,
    space: str | None = None,
) -> Any:
    """A map-style ``torch.utils.data.Dataset`` over a dataset folder.

    Each item is :func:`prepare_item` with arrays as tensors: every layer (``keys=None``) or
    the chosen ones, ``ids`` (a dict of int tensors), the cube when written, ``sample_id`` and
    ``scene``; images ``(C, H, W)`` float32, masks ``(1, H, W)`` bool. *transform*, if given,
    is applied to each item dict; *verify* is :func:`load_sample`'s. *relight* (a
    :class:`~spectrinsic.gt_export.relight.augment.RandomRelight`) replaces each sample by itself
    relit under random light spectra (samples built with ``--store-transport``). Random crops
    need *seed*: item *i* is cropped with
    ``default_rng([seed, i])``, the same on every worker and epoch. *max_residual_share* keeps
    only the samples whose RGB residual share is at most that fraction
    (:func:`filter_residual_share`). The spectral layers (``*_bands``, ``(31, H, W)``) come
    with the rest when the set was built with ``--spectral-layers``. *space* ``"srgb"``: the
    RGB layers' linear sRGB view (:func:`load_sample`). torch is imported only here.

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
    _check_space(space)
    folders = filter_residual_share(split_samples(dataset_dir, split), max_residual_share)
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
                sample = load_sample(folders[index], layers=wanted, verify=verify, space=space)
            else:
                relit = relight(folders[index], index, self.epoch)
                relit = srgb_view(relit, relit["meta"]) if space == "srgb" else relit
                sample = {
                    k: v for k, v in relit.items() if wanted is None or k in wanted or k == "meta"
                }
            rng = None if seed is None else np.random.default_rng([seed, index])
            item = tensors(
                prepare_item(sample, crop=crop, rng=rng, normalize_exposure=normalize_exposure)
            )
            return transform(item) if transform is not None else item

    return SpectrinsicDataset()


def working_space_view(
    sample: dict[str, Any], space: str = "acescg", *, clip: bool = False
) -> dict[str, np.ndarray]:
    """``image``, ``reflectance``, ``shading``, ``residual`` (and ``specular``) of a loaded
    sample built with ``--spectral-layers``, in another linear RGB working space (``"srgb"``,
    ``"rec2020"``, ``"acescg"``), from its band layers
    (:func:`~spectrinsic.gt_export.layers.spectral_intrinsics.bands_to_rgb`). Measured on 200
    generated rooms, ACEScg with unclipped shading halves linear sRGB's residual share (median
    and p95; docs/spectral-layers.md), hence the default working space of the stored RGB
    layers; for their sRGB view use ``load_sample(..., space="srgb")``. ``(H, W, 3)``
    float64, render units."""
    if "shading_bands" not in sample:
        raise DatasetError(
            "working_space_view needs the band layers: build the set with --spectral-layers"
        )
    to_xyz = sample["meta"]["render"]["to_xyz"]["bands31"]
    return bands_to_rgb(sample, to_xyz, working_space_matrix(space), clip=clip)
