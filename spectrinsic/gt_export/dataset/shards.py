"""WebDataset tar shards of a built dataset, for streaming training on large sets.

A shard is a plain POSIX tar in the `WebDataset <https://github.com/webdataset/webdataset>`_
convention: the members of one sample share its sample id as the key, and the part after the
first dot names the entry. Every array layer of :func:`spectrinsic.gt_export.load_sample` is
stored as ``<sample_id>.<layer>.npy`` (numpy's ``.npy`` format, the dtype and shape as loaded:
``(H, W, 3)`` float32 linear radiometric layers, ``(H, W)`` depth, bool mask, int32 ids), and the
sample's ``meta.json`` as ``<sample_id>.meta.json``. WebDataset lower-cases entry names and reads
a ``/`` as a folder, so a layer key is written lower-case with ``/`` as :data:`KEY_SEPARATOR`
(``image_camera/Nikon D50`` -> ``image_camera~nikon d50.npy``); the index's ``entries`` maps each
entry name back to its layer key.

Shards are made per split of the manifest (by scene, so no scene spans two splits), named
``<split>-<n:06d>.tar``, with at most *samples_per_shard* samples each, in sample-id order.
Members carry ``mtime = 0`` and fixed owners, so the same dataset gives byte-identical shards.
Each shard is written under a temporary name and renamed into place; the index
:data:`SHARD_INDEX` (shard names, sample counts, SHA-256, the layer names) is written last and
is what marks an export complete.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError, MissingDependencyError
from ...file_writes import replacing, write_text_file
from ..folders.outfolder import LOCK_NAME, check_out_folder, check_unlocked, folder_lock
from ..sample import MANIFEST_NAME, META_NAME, TMP_PREFIX, file_sha256, sample_dirs
from ..sample.meta import meta_from_bytes
from .loader import load_sample, split_samples
from .manifest import read_manifest

__all__ = [
    "SHARD_INDEX",
    "KEY_SEPARATOR",
    "ShardSet",
    "check_shard_folder",
    "write_shards",
    "shard_urls",
    "shard_dataset",
]

#: The export's index; written last, so its presence means every listed shard is complete.
SHARD_INDEX = "shards.json"
#: Stands for ``/`` of a layer key inside a tar member name.
KEY_SEPARATOR = "~"
_FORMAT = "spectrinsic-webdataset"
_VERSION = 1


@dataclass(frozen=True)
class ShardSet:
    """What :func:`write_shards` wrote: shard names per split and their sample counts."""

    folder: Path
    shards: dict[str, tuple[str, ...]]
    samples: dict[str, int]
    layers: tuple[str, ...]


def _webdataset() -> Any:
    try:
        import webdataset
    except ImportError as exc:
        raise MissingDependencyError(
            "tar shards need the webdataset package, which is not installed: "
            "pip install 'spectrinsic[shards]'"
        ) from exc
    return webdataset


def _member_name(layer: str) -> str:
    """``image_camera/Nikon D50`` -> ``image_camera~nikon d50.npy``."""
    if "." in layer or KEY_SEPARATOR in layer:
        raise DatasetError(
            f"layer {layer!r}: a shard entry name may not contain '.' or {KEY_SEPARATOR!r}"
        )
    return layer.replace("/", KEY_SEPARATOR).lower() + ".npy"


def _entries(layers: set[str]) -> dict[str, str]:
    """Entry name -> layer key; two keys differing only in case cannot share a shard."""
    entries = {_member_name(k): k for k in sorted(layers)}
    if len(entries) != len(layers):
        raise DatasetError(
            f"layers {sorted(layers)}: two differ only in case, which WebDataset merges"
        )
    return entries


def _npy(array: np.ndarray) -> bytes:
    stream = io.BytesIO()
    np.lib.format.write_array(stream, np.ascontiguousarray(array), allow_pickle=False)
    return stream.getvalue()


def _encode(sample: dict[str, Any]) -> dict[str, Any]:
    """One loaded sample -> the WebDataset record (entry name -> bytes)."""
    sample_id = str(sample["meta"]["sample_id"])
    if "." in sample_id:
        raise DatasetError(f"sample id {sample_id!r}: a WebDataset key may not contain '.'")
    record: dict[str, Any] = {"__key__": sample_id}
    for key, value in sample.items():
        if isinstance(value, np.ndarray):
            record[_member_name(key)] = _npy(value)
    record["meta.json"] = json.dumps(sample["meta"], sort_keys=True, allow_nan=False).encode(
        "utf-8"
    )
    return record


def check_shard_folder(out: Path, option: str = "--out") -> set[str]:
    """The files an earlier export of ours wrote in *out* (listed by its index, complete or
    interrupted); refuse a folder holding anything else, or one breaking the rule of every
    writing verb (:func:`~spectrinsic.gt_export.folders.outfolder.check_out_folder`). Writes nothing."""
    if check_out_folder(
        out,
        own=lambda p: (p / SHARD_INDEX).is_file(),
        option=option,
        what=f"an earlier shard export (no {SHARD_INDEX})",
    ):
        return set()
    index_path = out / SHARD_INDEX
    try:
        previous = json.loads(index_path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError) as exc:
        raise DatasetError(f"{index_path}: not a spectrinsic shard index ({exc})") from exc
    if not isinstance(previous, dict) or previous.get("format") != _FORMAT:
        raise DatasetError(f"{index_path}: not a spectrinsic shard index")
    ours = set(previous.get("files", {}))
    foreign = sorted(
        p.name
        for p in out.iterdir()
        if p.name not in ours | {SHARD_INDEX, LOCK_NAME} and not p.name.startswith(TMP_PREFIX)
    )
    if foreign:
        raise DatasetError(
            f"shard folder {str(out)!r} holds files spectrinsic did not write "
            f"({', '.join(foreign[:3])}{', ...' if len(foreign) > 3 else ''}); "
            "expected a new, empty or earlier shard folder"
        )
    return ours


def _write_index(out: Path, index: dict[str, Any]) -> None:
    write_text_file(out / SHARD_INDEX, json.dumps(index, indent=2, sort_keys=True, allow_nan=False))


def _plan(source: Path, samples_per_shard: int) -> dict[str, dict[str, list[Path]]]:
    """``{split: {shard name: sample folders}}`` in sample-id order."""
    plan: dict[str, dict[str, list[Path]]] = {}
    splits = _manifest(source).get("splits") or {}
    for split in list(splits) or [None]:
        folders = split_samples(source, split) if split is None or splits[split] else []
        label = split or "all"
        plan[label] = {
            f"{label}-{i // samples_per_shard:06d}.tar": folders[i : i + samples_per_shard]
            for i in range(0, len(folders), samples_per_shard)
        }
    return plan


def _write_shard(
    out: Path,
    name: str,
    folders: Sequence[Path],
    layers: Sequence[str] | None,
    progress: Callable[[str], None] | None,
) -> set[str]:
    """Write one shard under a temporary name, then rename it; return the layer keys seen."""
    wds = _webdataset()
    seen: set[str] = set()
    with replacing(out / name) as tmp, open(tmp, "wb") as stream:
        writer = wds.TarWriter(stream, mtime=0, user="spectrinsic", group="spectrinsic")
        try:
            for folder in folders:
                sample = load_sample(folder, layers=layers)
                seen.update(k for k, v in sample.items() if isinstance(v, np.ndarray))
                writer.write(_encode(sample))
                if progress is not None:
                    progress(folder.name)
        except BaseException:
            with contextlib.suppress(Exception):  # else tarfile flushes its buffer at
                writer.close()  # exit, into the closed file ("Exception ignored ...")
            raise
        writer.close()
    return seen


def _manifest(dataset_dir: Path) -> dict[str, Any]:
    manifest = read_manifest(dataset_dir)
    if manifest is None:
        raise DatasetError(f"{dataset_dir}: no readable {MANIFEST_NAME}; expected a built dataset")
    return dict(manifest.raw)


def write_shards(
    dataset_dir: str | os.PathLike[str],
    out_dir: str | os.PathLike[str],
    *,
    samples_per_shard: int = 1000,
    layers: Sequence[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> ShardSet:
    """Export the complete samples of *dataset_dir* as WebDataset shards in *out_dir*.

    Parameters
    ----------
    samples_per_shard
        Most samples in one shard (>= 1).
    layers
        Only these layer keys (default: every layer of each sample).
    progress
        Called with each sample id once its record is written.

    Raises
    ------
    DatasetError
        *out_dir* holds files spectrinsic did not write, lies inside a dataset, or the
        dataset has no manifest.
    FolderLockedError
        Another export holds *out_dir*.
    """
    if samples_per_shard < 1:
        raise DatasetError(f"samples per shard {samples_per_shard}; expected a whole number >= 1")
    source, out = Path(dataset_dir), Path(out_dir)
    check_export_source(source)
    check_shard_folder(out)
    with folder_lock(out):  # one export per folder; a second is refused, naming this one
        return _write_locked(
            source, out, check_shard_folder(out), samples_per_shard, layers, progress
        )


def check_export_source(source: Path, option: str = "DIR") -> None:
    """The dataset an export reads must be whole and at rest (writes nothing).

    Raises
    ------
    FolderLockedError
        A build holds the dataset's lock (a ``--rebuild`` running now would mix config hashes).
    DatasetError
        Samples the manifest lists are missing (an export would be partial): one line naming
        the first and how many.
    """
    check_unlocked(source, option)
    listed = sorted(_manifest(source).get("samples") or {})
    present = {p.name for p in sample_dirs(source)}
    missing = [name for name in listed if name not in present]
    if missing:
        more = f", and {len(missing) - 1} more" if len(missing) > 1 else ""
        raise DatasetError(
            f"{option} {str(source)!r}: {len(missing)} sample(s) listed in {MANIFEST_NAME} are "
            f"missing ({missing[0]!r}{more}); an export would be partial: run the build again"
        )


def _write_locked(
    source: Path,
    out: Path,
    ours: set[str],
    samples_per_shard: int,
    layers: Sequence[str] | None,
    progress: Callable[[str], None] | None,
) -> ShardSet:
    """:func:`write_shards` once the folder's lock is held; *ours*: files of an earlier export."""
    plan = _plan(source, samples_per_shard)
    planned = {name for shards in plan.values() for name in shards}
    base = {
        "format": _FORMAT,
        "version": _VERSION,
        "key_separator": KEY_SEPARATOR,
        "config_hash": _manifest(source).get("config_hash"),
        "n_scenes": len(
            {r.get("scene") for r in (_manifest(source).get("samples") or {}).values()}
        ),
    }
    # Before any shard: record every name this export may write, so a re-run after an
    # interruption knows them as its own (and nothing else in the folder is ever touched).
    _write_index(
        out, {**base, "complete": False, "files": dict.fromkeys(sorted(ours | planned), "")}
    )
    files: dict[str, str] = {}
    seen: set[str] = set()
    try:
        for shards in plan.values():
            for name, folders in shards.items():
                seen |= _write_shard(out, name, folders, layers, progress)
                files[name] = file_sha256(out / name)
        check_export_source(source)  # a build that started meanwhile: the export stays incomplete
        if _manifest(source).get("config_hash") != base["config_hash"]:
            raise DatasetError(f"DIR {str(source)!r} was rebuilt during the export; export again")
    except Exception:  # refused or a full disk (Ctrl-C keeps the index: a re-run finishes it)
        _roll_back(out, base, ours, set(files))
        raise
    _write_index(
        out,
        {
            **base,
            "complete": True,
            "entries": _entries(seen),
            "files": files,
            "splits": {
                k: {"shards": list(v), "samples": sum(map(len, v.values()))}
                for k, v in plan.items()
            },
        },
    )
    for stale in ours - planned:
        (out / stale).unlink(missing_ok=True)  # a shard an earlier export of ours wrote
    return ShardSet(
        out,
        {k: tuple(v) for k, v in plan.items()},
        {k: sum(map(len, v.values())) for k, v in plan.items()},
        tuple(sorted(seen)),
    )


def _roll_back(out: Path, base: dict[str, Any], ours: set[str], written: set[str]) -> None:
    """After a failed export, the index names no file that is not there: a first export's
    shards and index are removed (the folder is as before); an earlier export's index is
    rewritten (still incomplete) to list only the shards on disk."""
    if not ours:
        for name in written:
            (out / name).unlink(missing_ok=True)
        (out / SHARD_INDEX).unlink(missing_ok=True)
        return
    present = sorted(name for name in ours | written if (out / name).is_file())
    with contextlib.suppress(DatasetError):  # a full disk: the earlier index stays
        _write_index(out, {**base, "complete": False, "files": dict.fromkeys(present, "")})


def _index(out: Path) -> dict[str, Any]:
    try:
        index = json.loads((out / SHARD_INDEX).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError) as exc:
        raise DatasetError(f"{out}: no shard export ({SHARD_INDEX} missing or unreadable)") from exc
    if not isinstance(index, dict) or not index.get("complete"):
        raise DatasetError(f"{out}: the shard export was interrupted; run it again to finish")
    return index


def shard_urls(out_dir: str | os.PathLike[str], split: str | None = None) -> list[str]:
    """Paths of the shards of *split* (``None``: every split) from a complete export's index."""
    out = Path(out_dir)
    splits = _index(out)["splits"]
    if split is not None and split not in splits:
        raise DatasetError(f"split {split!r}; the shards have {sorted(splits)}")
    if split is not None and not splits[split]["samples"]:
        raise DatasetError(
            f"split {split!r} of {out} is empty: the dataset had "
            f"{_index(out).get('n_scenes', '?')} scene(s) for {len(splits)} splits"
        )
    chosen = [split] if split is not None else sorted(splits)
    return [str(out / name) for s in chosen for name in splits[s]["shards"]]


def _decoder(entries: dict[str, str]) -> Callable[[dict[str, Any]], dict[str, Any]]:
    """A raw WebDataset record (entry -> bytes) -> ``{layer: array, "meta": dict, ...}``; the
    ``meta.json`` entry read by :func:`~spectrinsic.gt_export.sample.meta.meta_from_bytes`."""

    def decode(record: dict[str, Any]) -> dict[str, Any]:
        item: dict[str, Any] = {"sample_id": record["__key__"]}
        for entry, value in record.items():
            if entry in entries:
                item[entries[entry]] = np.lib.format.read_array(
                    io.BytesIO(value), allow_pickle=False
                )
            elif entry == META_NAME:
                source = Path(str(record.get("__url__", "shard"))) / record["__key__"] / META_NAME
                item["meta"] = dict(meta_from_bytes(value, source).raw)
        return item

    return decode


def _verify_shards(urls: Sequence[str], index: dict[str, Any]) -> None:
    """Check every shard against the SHA-256 the index records, before any item is read."""
    recorded = index.get("files") or {}
    for url in urls:
        if not Path(url).is_file():
            raise DatasetError(f"{url}: listed in {SHARD_INDEX} but missing; export again")
        if file_sha256(url) != recorded.get(Path(url).name):
            raise DatasetError(
                f"{url}: does not match its SHA-256 in {SHARD_INDEX}; the shard is "
                "damaged, export again"
            )


def shard_dataset(
    out_dir: str | os.PathLike[str], split: str | None = None
) -> Iterator[dict[str, Any]]:
    """A ``webdataset.WebDataset`` over the shards of *split*, each item decoded as
    :func:`load_sample` returns it (arrays ``(H, W[, C])`` under their layer keys, ``meta``)
    plus ``sample_id``; an empty split is a :class:`~spectrinsic.errors.DatasetError` naming it.

    Every shard is first checked against its SHA-256 in :data:`SHARD_INDEX` (a damaged shard
    raises :class:`~spectrinsic.errors.DatasetError` before anything is yielded). It is an
    ``IterableDataset`` when torch is installed, so it feeds a
    ``torch.utils.data.DataLoader`` directly; chain ``.map(...)`` for crops or tensors.
    """
    wds = _webdataset()
    urls = shard_urls(out_dir, split)
    if not urls:
        return iter(())
    index = _index(Path(out_dir))
    _verify_shards(urls, index)
    decode = _decoder(index["entries"])
    return wds.WebDataset(urls, shardshuffle=False, empty_check=False).map(decode)
