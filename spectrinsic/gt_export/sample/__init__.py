"""The sample folder's vocabulary: file names, canonical JSON, hashes and the folder listing.

The bottom of ``gt_export``'s sample files: the writer (:mod:`~spectrinsic.gt_export.sample.writer`),
the reader (:mod:`~spectrinsic.gt_export.sample.meta`, the loader, check, gallery, shards) and
the integrity rules all take their names from here, and none of them from each other. A sample
folder ``<dataset>/<sample_id>/`` holds

* ``image.exr``, ``intrinsics.exr``, ``geometry.exr``, ... (float32 layers, integer ids as
  32-bit unsigned channels) and ``previews/<layer>.png``;
* :data:`SCENE_NAME`: the scene as plain data, compact canonical JSON;
* :data:`META_NAME`: provenance, layer records, the SHA-256 of every other file
  (:data:`HASHES_KEY`) and its own seal (:data:`SEAL_KEY`, see :func:`meta_seal`).

A dataset folder adds :data:`MANIFEST_NAME` (hashes of every sample file, splits, noise
summary) and :data:`CARD_NAME`.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping
from dataclasses import is_dataclass
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...file_writes import TMP_PREFIX  # one home: every sweep of temporaries knows it
from ...number_lists import copy_numbers, finite_numbers, numbers_only
from ...path_kinds import folder_problem
from ...scenes.model import record_fields

__all__ = [
    "FORMAT_VERSION",
    "READABLE_FORMATS",
    "META_NAME",
    "MANIFEST_NAME",
    "SCENE_NAME",
    "CARD_NAME",
    "PREVIEW_DIR",
    "TMP_PREFIX",
    "HASHES_KEY",
    "SEAL_KEY",
    "META_DIGITS",
    "plain_data",
    "canonical_json",
    "config_hash",
    "file_sha256",
    "meta_seal",
    "confined_path",
    "sample_dirs",
]

#: 3: integer ids as UINT channels, ``meta.json`` sealed by :data:`SEAL_KEY`; 2: shading from
#: spectral irradiance, residual, noise, denoised layers; 1: per-channel ratio shading.
FORMAT_VERSION = 3
#: Formats the readers accept (2: float32 ids, no seal; read, but never resumed).
READABLE_FORMATS = (2, 3)
META_NAME = "meta.json"
MANIFEST_NAME = "manifest.json"
#: The rendered scene as plain data (:func:`spectrinsic.scenes.model.scene_to_dict`), compact JSON.
SCENE_NAME = "scene.json"
#: The per-light transport of a sample built with ``dataset --store-transport``.
TRANSPORT_NAME = "transport.exr"
CARD_NAME = "DATASET.md"
PREVIEW_DIR = "previews"
#: Key of ``meta.json`` holding ``{relative path: SHA-256}`` of every file it lists.
HASHES_KEY = "sha256"
#: Key of ``meta.json`` holding :func:`meta_seal` of the rest of the file.
SEAL_KEY = "meta_sha256"
#: Significant digits of every float in ``meta.json`` (fitted matrices, light colours, noise
#: figures): far above their physical accuracy, and far enough below float64's 15.9 that the
#: last-bit differences of floating-point reductions between machines never reach the file.
META_DIGITS = 12


# ----------------------------------------------------------------------------------------------
# Canonical JSON


def plain_data(value: Any, digits: int | None = None) -> Any:
    """Plain JSON data of *value* (dataclasses, mappings, arrays, numpy scalars); floats rounded
    to *digits* significant digits if given; non-finite floats as their ``str`` (``"nan"``).

    >>> plain_data({"a": np.float32(0.5), "b": (1, np.int64(2)), "c": 1 / 3}, digits=3)
    {'a': 0.5, 'b': [1, 2], 'c': 0.333}
    """
    if is_dataclass(value) and not isinstance(value, type):
        # the fields scene_to_dict keeps (a material's gloss left out at its defaults, so matte
        # scenes are written as before it existed; a procedural texture's weights left out)
        return {k: plain_data(v, digits) for k, v in record_fields(value).items()}
    if isinstance(value, Mapping):
        return {str(k): plain_data(v, digits) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        finite = value.dtype.kind in "biu" or (value.dtype.kind == "f" and np.isfinite(value).all())
        if finite and (digits is None or value.dtype.kind != "f"):
            return value.tolist()  # plain bools, ints and finite floats all the way down
        return plain_data(value.tolist(), digits)
    if isinstance(value, np.generic):
        return plain_data(value.item(), digits)
    if isinstance(value, (list, tuple)):
        if digits is None and numbers_only(value) and finite_numbers(value):
            return copy_numbers(value)  # a mesh's numbers: already plain, without a call per value
        return [plain_data(v, digits) for v in value]
    if isinstance(value, float):
        if not np.isfinite(value):
            return str(value)
        return value if digits is None else float(f"{value:.{digits}g}")
    if value is None or isinstance(value, (str, int, bool)):
        return value
    return str(value)


def canonical_json(data: Any, *, compact: bool = False) -> str:
    """The text spectrinsic writes for plain *data*: sorted keys, UTF-8 characters kept, a final
    newline; indented by 2, or *compact* (one line, no spaces: the json module's C encoder,
    which indenting bypasses, for large files).

    >>> canonical_json({"b": 1, "a": [1, 2]}, compact=True)
    '{"a":[1,2],"b":1}\\n'
    """
    layout: dict[str, Any] = {"separators": (",", ":")} if compact else {"indent": 2}
    return json.dumps(data, sort_keys=True, ensure_ascii=False, **layout, allow_nan=False) + "\n"


def config_hash(config: Mapping[str, Any]) -> str:
    """The hash a sample records for *config*: equal settings, equal hashes.

    A config that carries its own ``"config_hash"`` (as ``DatasetConfig.to_dict()`` does) is
    trusted; otherwise the SHA-256 of its canonical JSON (sorted keys, no whitespace).

    >>> config_hash({"spp": 16, "seed": 1}) == config_hash({"seed": 1, "spp": 16})
    True
    >>> config_hash({"spp": 16, "config_hash": "abc"})
    'abc'
    """
    own = config.get("config_hash")
    if isinstance(own, str) and own:
        return own
    blob = json.dumps(
        plain_data(config),
        sort_keys=True,
        separators=(",", ":"),
        ensure_ascii=False,
        allow_nan=False,
    )
    return hashlib.sha256(blob.encode("utf-8")).hexdigest()


# ----------------------------------------------------------------------------------------------
# Hashes


def file_sha256(path: str | os.PathLike[str]) -> str:
    """SHA-256 hex digest of a file's bytes."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def meta_seal(meta: Mapping[str, Any]) -> str:
    """SHA-256 of the canonical JSON of a ``meta.json`` object without its :data:`SEAL_KEY`.

    ``meta.json`` records the hash of every other file of its sample, but a file cannot hold
    the hash of its own bytes; so it holds the hash of its content. Why here and not elsewhere:
    a sidecar file would be one more file to list, lose or overwrite apart from the record it
    guards, and ``manifest.json`` is written only when a build finishes, so it cannot guard the
    samples of an interrupted build, which is when a resume needs to judge them. The seal
    travels with the file, so the resume, ``check`` and the loader can each verify it alone.

    It is a hash of the parsed content, not of the bytes: JSON round-trips every number
    ``meta.json`` holds exactly (floats are written by ``repr``), so the canonical compact text
    of the parsed object is the text the writer hashed, and any changed character of a key or
    value changes it (reformatting the whitespace alone does not).

    >>> meta_seal({"a": 1, SEAL_KEY: "x"}) == meta_seal({"a": 1})
    True
    """
    body = {k: v for k, v in meta.items() if k != SEAL_KEY}
    # the compact form: the json module's C encoder (indenting is 5x slower, as long as the
    # rest of reading the file), and the same hash whatever the file's layout
    return hashlib.sha256(canonical_json(body, compact=True).encode("utf-8")).hexdigest()


# ----------------------------------------------------------------------------------------------
# Paths and listing


def confined_path(folder: Path, rel: object) -> Path | None:
    """``folder/rel`` if *rel* is a relative POSIX path that stays inside *folder* (symbolic
    links resolved), else ``None``.

    >>> confined_path(Path("/data/s"), "../../outside/secret.exr") is None
    True
    """
    if not isinstance(rel, str) or not rel or "\\" in rel:
        return None
    pure = PurePosixPath(rel)
    if pure.is_absolute() or ".." in pure.parts:
        return None
    # without ".." a path leaves the folder only through a symbolic link: follow links only
    # when one of its own components is one (resolving every path costs ~0.3 ms each)
    here = folder
    for part in pure.parts:
        here = here / part
        if here.is_symlink():
            root = folder.resolve()
            path = (folder / pure).resolve()
            return folder / pure if path.is_relative_to(root) and path != root else None
    return folder / pure


def sample_dirs(dataset_dir: str | os.PathLike[str]) -> list[Path]:
    """Sample folders of a dataset (visible sub-folders holding ``meta.json``), sorted by name."""
    root = Path(dataset_dir)
    if (problem := folder_problem(root)) is not None:
        raise DatasetError(f"dataset folder {str(root)!r} {problem}")
    return sorted(
        p
        for p in root.iterdir()
        if p.is_dir() and not p.name.startswith(".") and (p / META_NAME).is_file()
    )
