"""Reading ``meta.json``: the one parser of a sample's record, validated into frozen records.

Every reader of a sample folder (the loader, ``check``, the resume's integrity test, the
manifest and card, the gallery, the shards, and through the loader the evaluation) gets its
``meta.json`` from :func:`read_meta`. A damaged file fails here, once, with one line naming the
file and the field (:class:`~spectrinsic.errors.SampleMetaError`), instead of as a ``KeyError``
deep inside whichever reader indexed it first:

* not JSON, or a JSON ``NaN``/``Infinity`` (the writer never writes them); a field missing, a field spectrinsic does not write (a bit flip in a key does both), or a
  field of the wrong type (``"seed": "7"``, a negative size, a layer file outside the folder);
* content that no longer matches its seal (:func:`~spectrinsic.gt_export.sample.meta_seal`),
  e.g. one digit of a fitted matrix edited by hand.

:func:`owned_files` is the lenient question the writer asks before replacing a folder: did
spectrinsic write this ``meta.json`` (then its folder may be rebuilt, even when damaged)?
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

from ...errors import SampleMetaError
from ..layers.gloss import SPECULAR
from . import (
    HASHES_KEY,
    META_NAME,
    READABLE_FORMATS,
    SEAL_KEY,
    TRANSPORT_NAME,
    confined_path,
    meta_seal,
)
from .json_fields import JsonFields, load_json, reject_constant

__all__ = [
    "LayerRecord",
    "NoiseFigure",
    "LightEntry",
    "Identity",
    "SampleMeta",
    "read_meta",
    "parse_meta",
    "owned_files",
    "meta_from_bytes",
]

#: Every top-level field of ``meta.json`` (format 3 adds :data:`SEAL_KEY`).
META_FIELDS = frozenset(
    {
        "format_version",
        "sample_id",
        "scene",
        "scene_hash",
        "scene_metadata",
        "config_hash",
        "seed",
        "variants",
        "render",
        "reference_mode",
        "size",
        "spectral_grid",
        "materials",
        "objects",
        "lights",
        "cameras",
        "cube_sensors",
        "matrices",
        "layers",
        "identities",
        "denoised_layers",
        "noise",
        "shading_clipping",
        "files",
        "versions",
        HASHES_KEY,
    }
)
#: Fields written only by some builds: ``transport`` (``--store-transport``, see
#: :func:`~spectrinsic.gt_export.sample.transport_exr.write_transport`), ``sensor`` (``--camera``),
#: ``spectrum_files`` (``csv:`` spectra, :func:`~spectrinsic.spectra.user_spectra.spectrum_files`),
#: ``residual_share``, ``working_space`` (issue 30; none: linear sRGB), ``semantic_classes``
#: (issue 41), ``storage`` (issue 45, :mod:`~spectrinsic.gt_export.sample.layer_storage`).
OPTIONAL_META_FIELDS = frozenset(
    "transport sensor spectrum_files residual_share working_space semantic_classes storage".split()
)
_LAYER_FIELDS = frozenset(
    {
        "file",
        "exr_layer",
        "channels",
        "shape",
        "dtype",
        "units",
        "nonnegative",
        "preview",
        "preview_encoding",
    }
)
_NOISE_FIELDS = frozenset({"median", "p95", "rms", "pixels"})
#: Noise records of format 2 may lack ``rms`` (it then reads as the median).
_NOISE_REQUIRED = frozenset({"median", "p95", "pixels"})
_IDENTITY_FIELDS = ("image", "reflectance", "shading", "residual")


@dataclass(frozen=True)
class LayerRecord:
    """Where a layer lies and what it holds (``meta.json["layers"][key]``)."""

    #: File inside the sample folder (``"intrinsics.exr"``), checked to stay inside it.
    file: str
    #: Layer name inside the EXR file (the key before any ``/camera``).
    exr_layer: str
    channels: tuple[str, ...]
    #: ``(H, W)`` or ``(H, W, C)``.
    shape: tuple[int, ...]
    dtype: str
    units: str  #: units and encoding, in words
    nonnegative: bool
    #: Preview PNG inside the sample folder, or ``None``.
    preview: str | None
    #: How the preview's pixels encode the layer (``{"kind": "srgb", "scale": k}``...).
    preview_encoding: Mapping[str, Any] | None


@dataclass(frozen=True)
class NoiseFigure:
    """Relative standard error of a raw layer over the lit pixels (fractions, not %)."""

    median: float
    p95: float
    rms: float
    pixels: int


@dataclass(frozen=True)
class LightEntry:
    """The fields of a light that readers use; the rest stays in :attr:`SampleMeta.raw`."""

    name: str
    kind: str
    spectrum: str
    xy: tuple[float, float]  #: CIE 1931 xy chromaticity
    srgb: tuple[float, ...]  #: linear sRGB colour at unit luminance
    #: Fraction of the image's luminance due to this light.
    share: float
    #: SPD on ``spectral_grid.lights_spd`` (unit luminance).
    spd: tuple[float, ...]


@dataclass(frozen=True)
class Identity:
    """``image = reflectance ∘ shading [+ specular] + residual``, by layer key (``specular``
    only in samples of glossy scenes)."""

    image: str
    reflectance: str
    shading: str
    residual: str
    specular: str | None = None


@dataclass(frozen=True)
class SampleMeta:
    """A validated ``meta.json``. :attr:`raw` is the parsed object itself, read-only."""

    #: The ``meta.json`` file read.
    path: Path
    format_version: int
    sample_id: str
    scene: str
    config_hash: str
    seed: int
    variants: tuple[str, ...]
    reference_mode: str
    #: ``(height, width)`` in pixels.
    size: tuple[int, int]
    scene_metadata: Mapping[str, Any]
    #: Material id (as a string) -> spectrum name.
    materials: Mapping[str, str]
    lights: tuple[LightEntry, ...]
    #: Camera sensor sets of the per-camera layers, without their ``camera:`` prefix.
    cameras: tuple[str, ...]
    cube_sensors: str | None
    layers: Mapping[str, LayerRecord]
    identities: tuple[Identity, ...]
    noise: Mapping[str, NoiseFigure]
    #: Files of the sample (relative POSIX paths, inside it) and their SHA-256.
    files: tuple[str, ...]
    hashes: Mapping[str, str]
    #: Whether the content matched its seal (``None``: format 2 has none; not verified).
    sealed: bool | None
    raw: Mapping[str, Any] = field(repr=False)
    #: The stored per-light transport's record (``transport.exr``), ``None`` when not stored.
    transport: Mapping[str, Any] | None = None

    @property
    def folder(self) -> Path:
        return self.path.parent


def _layer(f: JsonFields, rec: object, name: str) -> LayerRecord:
    rec = f.mapping(rec, name)
    for key in ("file", "exr_layer"):  # where the data is: named first when missing
        if key not in rec:
            raise SampleMetaError(f"{f.path}: {name}.{key}: missing")
    f.exact_keys(rec, name, _LAYER_FIELDS)
    shape = tuple(
        f.integer(v, f"{name}.shape[{i}]", low=1)
        for i, v in enumerate(f.sequence(rec["shape"], f"{name}.shape"))
    )
    if len(shape) not in (2, 3):
        raise f.fail(f"{name}.shape", "(H, W) or (H, W, C)", list(shape))
    encoding = rec["preview_encoding"]
    if encoding is not None:
        f.numeric_tree(f.mapping(encoding, f"{name}.preview_encoding"), f"{name}.preview_encoding")
    preview = rec["preview"]
    if not isinstance(rec["nonnegative"], bool):
        raise f.fail(f"{name}.nonnegative", "true or false", rec["nonnegative"])
    return LayerRecord(
        file=f.inside(rec["file"], f"{name}.file"),
        exr_layer=f.text(rec["exr_layer"], f"{name}.exr_layer"),
        channels=f.texts(rec["channels"], f"{name}.channels"),
        shape=shape,
        dtype=f.text(rec["dtype"], f"{name}.dtype"),
        units=f.text(rec["units"], f"{name}.units"),
        nonnegative=rec["nonnegative"],
        preview=None if preview is None else f.inside(preview, f"{name}.preview"),
        preview_encoding=encoding,
    )


def _noise(f: JsonFields, noise: object) -> dict[str, NoiseFigure]:
    out = {}
    for key, fig in f.mapping(noise, "noise").items():
        name = f"noise.{key}"
        if key == "batches":
            f.integer(fig, name, low=2)
            continue
        fig = f.mapping(fig, name)
        f.exact_keys(fig, name, _NOISE_FIELDS, _NOISE_REQUIRED)
        median, p95 = f.number(fig["median"], f"{name}.median"), f.number(fig["p95"], f"{name}.p95")
        rms = f.number(fig.get("rms", median), f"{name}.rms")
        out[key] = NoiseFigure(median, p95, rms, pixels=f.integer(fig["pixels"], f"{name}.pixels"))
    return out


def _light(f: JsonFields, light: object, name: str) -> LightEntry:
    light = f.mapping(light, name)
    for key in ("name", "kind", "spectrum", "xy", "srgb", "share", "spd"):
        if key not in light:
            raise SampleMetaError(f"{f.path}: {name}.{key}: missing")
    f.numeric_tree(light, name)
    xy = f.numbers(light["xy"], f"{name}.xy")
    if len(xy) != 2:
        raise f.fail(f"{name}.xy", "two numbers", list(xy))
    return LightEntry(
        name=f.text(light["name"], f"{name}.name"),
        kind=f.text(light["kind"], f"{name}.kind"),
        spectrum=f.text(light["spectrum"], f"{name}.spectrum"),
        xy=(xy[0], xy[1]),
        srgb=f.numbers(light["srgb"], f"{name}.srgb"),
        share=f.number(light["share"], f"{name}.share"),
        spd=f.numbers(light["spd"], f"{name}.spd"),
    )


def _identity(f: JsonFields, ident: object, name: str, held: Mapping[str, LayerRecord]) -> Identity:
    ident = f.mapping(ident, name)
    fields = _IDENTITY_FIELDS + ((SPECULAR,) if SPECULAR in ident else ())
    f.exact_keys(ident, name, frozenset(fields))
    keys = [f.text(ident[k], f"{name}.{k}") for k in fields]
    for k, key in zip(fields, keys, strict=True):
        if key not in held:
            raise f.fail(f"{name}.{k}", "a layer of this sample", key)
    return Identity(*keys)


def _files(f: JsonFields, meta: Mapping[str, Any]) -> tuple[tuple[str, ...], dict[str, str]]:
    files = tuple(
        f.inside(rel, f"files[{i}]") for i, rel in enumerate(f.sequence(meta["files"], "files"))
    )
    hashes = f.mapping(meta[HASHES_KEY], HASHES_KEY)
    if set(hashes) != set(files):
        odd = sorted(set(hashes) ^ set(files))[0]
        raise f.fail(HASHES_KEY, "one SHA-256 per listed file", odd)
    for rel, digest in hashes.items():
        if not isinstance(digest, str) or len(digest) != 64:
            raise f.fail(f"{HASHES_KEY}.{rel}", "a SHA-256 hex digest", digest)
    return files, dict(hashes)


# ----------------------------------------------------------------------------------------------
# The reader


def _sealed(f: JsonFields, meta: Mapping[str, Any], verify: bool) -> bool:
    if not isinstance(meta[SEAL_KEY], str):
        raise f.fail(SEAL_KEY, "a SHA-256 hex digest", meta[SEAL_KEY])
    sealed = meta_seal(meta) == meta[SEAL_KEY]
    if verify and not sealed:
        raise SampleMetaError(
            f"{f.path}: {SEAL_KEY}: the content does not match its seal "
            "(edited or damaged after it was written)"
        )
    return sealed


def _size(f: JsonFields, value: object) -> tuple[int, int]:
    size = tuple(f.integer(v, f"size[{i}]", low=1) for i, v in enumerate(f.sequence(value, "size")))
    if len(size) != 2:
        raise f.fail("size", "[height, width]", list(size))
    return size[0], size[1]


def _check_records(f: JsonFields, meta: Mapping[str, object]) -> None:
    """The fields kept as plain JSON in :class:`SampleMeta` (``raw``): checked for type only."""
    for name in ("matrices", "spectral_grid", "shading_clipping", "render"):
        f.numeric_tree(f.mapping(meta[name], name), name)
    for name in ("residual_share", "working_space"):  # samples since issue 30
        f.numeric_tree(f.mapping(meta.get(name, {}), name), name)
    for name in ("objects", "versions", "semantic_classes"):
        for key, value in f.mapping(meta.get(name, {}), name).items():
            f.text(value, f"{name}.{key}")
    f.texts(meta["denoised_layers"], "denoised_layers")
    f.text(meta["scene_hash"], "scene_hash")


def parse_meta(meta: object, path: Path, *, verify: bool = True) -> SampleMeta:
    """Validate a parsed ``meta.json`` (*path* names it in errors and locates its folder).

    *verify* also checks the content against its seal (format 3).

    Raises
    ------
    SampleMetaError
        One line naming *path* and the first field that is not as spectrinsic writes it.
    """
    f = JsonFields(path)
    meta = f.mapping(meta, "top level")
    version = meta.get("format_version")
    if version not in READABLE_FORMATS or isinstance(version, bool):
        raise f.fail("format_version", f"one of {list(READABLE_FORMATS)}", version)
    required = META_FIELDS | ({SEAL_KEY} if version >= 3 else set())
    f.exact_keys(meta, "", required | OPTIONAL_META_FIELDS, required)
    sample_id = f.text(meta["sample_id"], "sample_id")
    if sample_id != path.parent.name:
        raise f.fail("sample_id", f"the folder's name {path.parent.name!r}", sample_id)
    layers = {
        key: _layer(f, rec, f"layers.{key}")
        for key, rec in f.mapping(meta["layers"], "layers").items()
    }
    size = _size(f, meta["size"])
    _check_records(f, meta)
    materials = f.mapping(meta["materials"], "materials")
    files, hashes = _files(f, meta)
    transport = None
    if "transport" in meta:
        transport = MappingProxyType(f.mapping(meta["transport"], "transport"))
        if TRANSPORT_NAME not in files:
            raise f.fail(
                "transport", "a record of a transport file the sample lists", dict(transport)
            )
    record = SampleMeta(
        path=path,
        format_version=version,
        sample_id=sample_id,
        scene=f.text(meta["scene"], "scene"),
        config_hash=f.text(meta["config_hash"], "config_hash"),
        seed=f.integer(meta["seed"], "seed"),
        variants=f.texts(meta["variants"], "variants"),
        reference_mode=f.text(meta["reference_mode"], "reference_mode"),
        size=size,
        scene_metadata=MappingProxyType(f.mapping(meta["scene_metadata"], "scene_metadata")),
        materials=MappingProxyType({k: f.text(v, f"materials.{k}") for k, v in materials.items()}),
        lights=tuple(
            _light(f, v, f"lights[{i}]") for i, v in enumerate(f.sequence(meta["lights"], "lights"))
        ),
        cameras=f.texts(meta["cameras"], "cameras"),
        cube_sensors=f.text(meta["cube_sensors"], "cube_sensors", optional=True),
        layers=MappingProxyType(layers),
        identities=tuple(
            _identity(f, v, f"identities[{i}]", layers)
            for i, v in enumerate(f.sequence(meta["identities"], "identities"))
        ),
        noise=MappingProxyType(_noise(f, meta["noise"])),
        files=files,
        hashes=MappingProxyType(hashes),
        sealed=None,
        raw=MappingProxyType(meta),
        transport=transport,
    )
    # the seal last: a field that is wrong is named above; this catches what no schema can
    return replace(record, sealed=_sealed(f, meta, verify)) if version >= 3 else record


def meta_from_bytes(data: bytes, path: Path, *, verify: bool = True) -> SampleMeta:
    """:func:`parse_meta` of a ``meta.json`` carried elsewhere (a shard's ``<id>.meta.json``);
    *path* is where it came from, ``<somewhere>/<sample_id>/meta.json``."""
    try:
        parsed = json.loads(data.decode("utf-8"), parse_constant=reject_constant)
    except (ValueError, RecursionError) as exc:  # RecursionError: nesting too deep
        raise SampleMetaError(f"{path}: not valid JSON ({exc})") from exc
    return parse_meta(parsed, path, verify=verify)


def read_meta(folder: str | os.PathLike[str], *, verify: bool = True) -> SampleMeta:
    """Read and validate ``<folder>/meta.json`` (see the module notes).

    Parameters
    ----------
    folder
        A sample folder.
    verify
        Also check the content against its seal; ``False`` reads an edited file (``check``
        reports the edit and still compares its config hash).

    Raises
    ------
    SampleMetaError
        One line naming the file and the field.
    """
    path = Path(folder) / META_NAME
    return parse_meta(load_json(path), path, verify=verify)


def owned_files(folder: Path) -> frozenset[str] | None:
    """The files a ``meta.json`` spectrinsic wrote lists (inside *folder*), or ``None`` if
    *folder* holds no such ``meta.json``.

    Lenient on purpose: it asks who wrote the folder, not whether the record is sound, so a
    damaged sample can still be rebuilt. A JSON object naming *folder* as its sample and
    listing files inside it counts as spectrinsic's.
    """
    try:
        meta = json.loads((folder / META_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    if not isinstance(meta, dict) or meta.get("sample_id") != folder.name:
        return None
    files = meta.get("files")
    if not isinstance(files, list) or not all(confined_path(folder, f) for f in files):
        return None
    return frozenset(files)
