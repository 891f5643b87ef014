"""How a sample's layers lie in its EXR files (issue 45): in full, or as the factors they are
made of, rebuilt bit for bit by every reader (``load_sample``, ``spectrinsic check``).

``meta.json["storage"]["layers"]`` names the *form* of every layer that is not stored in full:

* ``"coverage_table"`` (``reflectance_bands``): ``float32(coverage @ table)`` summed in
  material order (:func:`~spectrinsic.gt_export.layers.irradiance.coverage_albedo`, the
  writer's own product: the same bits on every machine). ``coverage``
  ``(H, W, M)`` is the render's per-material pixel coverage (a textured hit's share split over
  its basis materials by the texel's weights), stored as the float32 layer :data:`COVERAGE_LAYER`
  of the same file (channels ``m0 …``); ``table`` ``(M, K)`` is every material's band albedo,
  stored once as the file's header attribute ``spectrinsic.table.<layer>`` (JSON; float64
  written as its shortest repr, so it reads back exactly).
* ``"band_image"`` (``image_bands`` of a denoised sample):
  :func:`~spectrinsic.gt_export.layers.spectral_intrinsics.band_image` of that albedo (float64),
  ``shading_bands``, the pixels surfaces cover (coverage sum ≥
  :data:`~spectrinsic.gt_export.layers.irradiance.COVERAGE_MIN`), ``image_bands_raw`` and
  ``specular_bands``.
* ``"transport_sum"`` (``image_bands_raw``, or ``image_bands`` where not denoised, of a
  sample that stores its transport): ``Σ_l T̄_l ∘ ē_l`` of the transport's stored batch means
  and the lights' band means in the file's header
  (:mod:`~spectrinsic.gt_export.sample.transport_cube`, which defines the cube so).
* ``"ratio"`` (``shading_ratio``): :func:`~spectrinsic.gt_export.layers.imaging.shading_ratio`
  of ``image`` and ``reflectance``.
* ``"unit_luminance"`` (``illuminant``, ``illuminant_camera/<name>``):
  :func:`~spectrinsic.gt_export.layers.irradiance.unit_luminance` of the space's shading and
  ``shading_grey``.
* ``"identity_residual"`` (the residual of an identity in ``meta.json["identities"]``):
  :func:`~spectrinsic.gt_export.layers.irradiance.residual` of the identity's terms.

Estimates outside every identity (the noise maps,
:data:`~spectrinsic.gt_export.sample.stored_layers.HALF_PREFIXES`) are stored as float16 where
their values fit (``meta.json["storage"]["half"]``); readers return them as float32, within
2**-11 of the computed values (2**-24 absolute below 6.1e-5, where float16 is subnormal).

``meta.json["storage"]["terms"]`` lists the layers each rebuilt layer is made of (in that
order) and ``["sha256"]`` the SHA-256 of its float32 values (:func:`layer_sha256`) as the writer
computed them (from the float32 values of its terms, as stored); readers compare the rebuild
with it. The writer stores a layer as its factors only where the rebuild gives it back bit for
bit (:mod:`~spectrinsic.gt_export.sample.stored_layers` tries every sample), else in full. The
files' SHA-256 cover the coverage and the table, the seal of ``meta.json`` the layers' hashes,
so ``check`` finds a tampered table or term. Samples without a storage record (before issue 45)
hold every layer in full and read as before. A residual rebuilt from its identity's terms
satisfies the identity by construction; its recorded hash is what ``check`` verifies.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...render.algebra.shares import compose
from ..formats.exr import read_exr, read_exr_attributes
from ..layers.imaging import shading_ratio
from ..layers.irradiance import coverage_albedo, covered, residual, unit_luminance
from ..layers.spectral_intrinsics import band_image
from .transport_cube import read_cube_factors
from .transport_exr import COVERAGE_LAYER  # one name for the per-material coverage layer

__all__ = [
    "FORMS",
    "COVERAGE_LAYER",
    "BAND_FACTORS",
    "BAND_FORMS",
    "TABLE_ATTRIBUTE",
    "rebuild",
    "storage_forms",
    "layer_sha256",
    "rebuilt_mismatches",
    "storage_summary",
    "read_layers",
    "rebuild_layers",
]

#: The forms a layer may be stored in besides in full (module notes).
FORMS = (
    "coverage_table",
    "band_image",
    "transport_sum",
    "ratio",
    "unit_luminance",
    "identity_residual",
)
#: How many terms each form is rebuilt from (besides a file's coverage and table).
_TERM_COUNTS = {
    "coverage_table": (0,),
    "band_image": (3, 4),
    "transport_sum": (0,),
    "ratio": (2,),
    "unit_luminance": (2,),
    "identity_residual": (3, 4),
}
#: The forms rebuilt from the coverage and the band table of their file.
BAND_FORMS = ("coverage_table", "band_image")
#: Header attribute of the file holding a ``coverage_table`` layer: its ``(M, K)`` table.
TABLE_ATTRIBUTE = "spectrinsic.table.{layer}"
#: The terms of ``image_bands`` (``band_image``), then ``specular_bands`` in glossy scenes.
BAND_FACTORS = ("reflectance_bands", "shading_bands", "image_bands_raw")
#: Largest table a header may declare (materials × bands), so a damaged file cannot make the
#: reader allocate without bound.
_TABLE_MAX = 1 << 20


def layer_sha256(array: np.ndarray) -> str:
    """SHA-256 of a layer's values: float32 little-endian, C order ``(H, W[, C])`` (of a
    rebuilt layer, recorded in ``meta.json["storage"]["sha256"]``)."""
    return hashlib.sha256(np.ascontiguousarray(array, "<f4").tobytes()).hexdigest()


def _f64(values: Mapping[str, np.ndarray], key: str) -> np.ndarray:
    return np.asarray(values[key], np.float64)


def rebuild(
    key: str,
    form: str,
    terms: Sequence[str],
    values: Mapping[str, np.ndarray],
    factors: tuple[np.ndarray, np.ndarray] | None,
) -> np.ndarray:
    """The float32 layer *key* of *form* from the float32 *values* of its *terms* and, for the
    band layers, ``(coverage, table)``; for ``transport_sum``, ``(means, ē)``."""
    if form == "transport_sum":
        if factors is None:
            raise DatasetError(f"layer {key!r} ({form}) needs its transport's means")
        out = compose(*factors)
    elif form == "identity_residual":
        out = residual(*(values[t] for t in terms))
    elif form == "ratio":
        out = shading_ratio(values[terms[0]], values[terms[1]])
    elif form == "unit_luminance":
        out = unit_luminance(_f64(values, terms[0]), _f64(values, terms[1]))
    else:
        if factors is None:
            raise DatasetError(f"layer {key!r} ({form}) needs its coverage and table")
        albedo = coverage_albedo(*factors)
        if form == "coverage_table":
            out = albedo
        else:  # band_image: terms reflectance, shading, raw cube (, specular)
            out = band_image(
                albedo,
                _f64(values, terms[1]),
                covered(factors[0]),
                _f64(values, terms[2]),
                _f64(values, terms[3]) if len(terms) > 3 else None,
            )
    return np.asarray(out, np.float32)


def storage_forms(meta: Mapping[str, Any], layers: Mapping[str, Any]) -> dict[str, str]:
    """``{layer: form}`` of the layers a ``meta.json`` says are stored as factors (empty for
    samples before issue 45); one-line :class:`DatasetError` for an unknown form or layer, or
    a record without every such layer's terms and SHA-256."""
    record = meta.get("storage")
    if record is None:
        return {}
    forms = record.get("layers") if isinstance(record, Mapping) else None
    if not isinstance(forms, Mapping):
        raise DatasetError("meta.json: storage.layers: expected an object of layer -> form")
    for key, form in forms.items():
        if form not in FORMS or key not in layers:
            raise DatasetError(
                f"meta.json: storage.layers.{key}: {form!r}; expected a listed layer stored "
                f"as one of {list(FORMS)}"
            )
    hashes, terms = record.get("sha256"), record.get("terms")
    if not (isinstance(hashes, Mapping) and set(hashes) == set(forms)):
        raise DatasetError(
            "meta.json: storage.sha256: expected the SHA-256 of every layer in storage.layers"
        )
    if not (
        isinstance(terms, Mapping)
        and set(terms) == set(forms)
        and all(
            isinstance(t, list)
            and len(t) in _TERM_COUNTS[str(forms[k])]
            and all(isinstance(x, str) and x in layers and x != k for x in t)
            for k, t in terms.items()
        )
    ):
        raise DatasetError(
            "meta.json: storage.terms: expected for every layer in storage.layers the list of "
            "listed layers it is rebuilt from, as many as its form takes"
        )
    return {str(k): str(v) for k, v in forms.items()}


def storage_summary(metas: Iterable[Mapping[str, Any]]) -> dict[str, Any]:
    """The manifest's record of how its samples' layers are stored: ``{form: [layer, ...]}``
    of the rebuilt layers over every sample (the others are stored in full), the float16
    layers, and how many samples have no storage record (before issue 45: all in full)."""
    forms: dict[str, set[str]] = {}
    half: set[str] = set()
    old = 0
    for meta in metas:
        record = meta.get("storage")
        if not isinstance(record, Mapping):
            old += 1
            continue
        for key, form in (record.get("layers") or {}).items():
            forms.setdefault(str(form), set()).add(str(key))
        half.update(str(k) for k in record.get("half") or ())
    return {
        "as_factors": {form: sorted(keys) for form, keys in sorted(forms.items())},
        "float16": sorted(half),
        "samples_without_record": old,
        "doc": "docs/sample-storage.md",
    }


def _terms(meta: Mapping[str, Any]) -> dict[str, list[str]]:
    """``meta.json["storage"]["terms"]`` (validated by :func:`storage_forms` first)."""
    return {str(k): list(v) for k, v in ((meta.get("storage") or {}).get("terms") or {}).items()}


def rebuilt_mismatches(meta: Mapping[str, Any], values: Mapping[str, np.ndarray]) -> list[str]:
    """The rebuilt layers among *values* whose :func:`layer_sha256` is not the one
    ``meta.json["storage"]["sha256"]`` records (the layer the writer computed)."""
    hashes = (meta.get("storage") or {}).get("sha256") or {}
    return [k for k in sorted(hashes) if k in values and layer_sha256(values[k]) != hashes[k]]


def _table(path: Path, key: str, coverage: np.ndarray, bands: int) -> np.ndarray:
    """The ``(M, K)`` table of *key* from *path*'s header, checked against its coverage."""
    name = TABLE_ATTRIBUTE.format(layer=key)
    text = read_exr_attributes(path).get(name)
    try:
        table = (
            np.asarray(json.loads(str(text)), np.float64)
            if len(str(text)) < _TABLE_MAX * 32
            else None
        )
    except (ValueError, TypeError, RecursionError):
        table = None
    if table is None or table.shape != (coverage.shape[-1], bands) or not np.isfinite(table).all():
        raise DatasetError(
            f"EXR file {str(path)!r}: header attribute {name!r} is not a "
            f"{coverage.shape[-1]} x {bands} table of finite band albedos"
        )
    return table


def _closure(
    keys: Sequence[str] | None,
    forms: Mapping[str, str],
    terms: Mapping[str, Sequence[str]],
) -> set[str]:
    """The factor-stored layers that *keys* (default all) need, themselves included."""
    needed = set(forms if keys is None else (k for k in keys if k in forms))
    stack = list(needed)
    while stack:
        key = stack.pop()
        for dep in terms[key]:
            if dep in forms and dep not in needed:
                needed.add(dep)
                stack.append(dep)
    return needed


def _field(record: Any, name: str) -> Any:
    return record[name] if isinstance(record, Mapping) else getattr(record, name)


def rebuild_layers(
    meta: Mapping[str, Any],
    records: Mapping[str, Any],
    values: dict[str, np.ndarray],
    path_of: Callable[[str], Path],
    *,
    wanted: Sequence[str] | None = None,
    coverage: Mapping[str, np.ndarray] | None = None,
) -> dict[str, np.ndarray]:
    """Add to *values* (stored layers already read, by key) the layers of *meta*'s storage
    record that *wanted* need (default all), rebuilt from their factors. Factors not in
    *values*, and coverage layers not in *coverage* (by file), are read through *path_of* (file
    name -> path, e.g. after a hash check). Returns *values*."""
    forms = storage_forms(meta, records)
    terms = _terms(meta)
    pending = {k: forms[k] for k in sorted(_closure(wanted, forms, terms)) if k not in values}
    factors: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    while pending:
        ready = [k for k, f in pending.items() if not set(terms[k]) & set(pending)]
        if not ready:
            raise DatasetError(f"meta.json: storage.layers {sorted(pending)} depend on each other")
        for key in ready:
            form = pending.pop(key)
            _read_missing(records, values, [n for n in terms[key] if n not in values], path_of)
            file_factors = None
            if form == "transport_sum":
                rec = records[key]
                cube = read_cube_factors(
                    meta, path_of, str(_field(rec, "file")), key, len(_field(rec, "channels"))
                )
                file_factors = (cube.means, cube.light_means)
            elif form in BAND_FORMS:
                file = str(_field(records[key], "file"))
                if file not in factors:
                    factors[file] = _factors(path_of(file), file, records, forms, coverage)
                file_factors = factors[file]
            try:
                values[key] = rebuild(key, form, terms[key], values, file_factors)
            except ValueError as exc:  # terms of other shapes than the layer (a damaged file)
                raise DatasetError(
                    f"layer {key!r} cannot be rebuilt from {terms[key]}: {exc}"
                ) from exc
    return values


def _factors(
    path: Path,
    file: str,
    records: Mapping[str, Any],
    forms: Mapping[str, str],
    coverage: Mapping[str, np.ndarray] | None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(coverage, table)`` of the ``coverage_table`` layer stored in *file* (at *path*)."""
    table_key = next(
        (
            k
            for k, f in forms.items()
            if f == "coverage_table" and _field(records[k], "file") == file
        ),
        None,
    )
    if table_key is None:
        raise DatasetError(f"meta.json: storage.layers: no coverage_table layer in {file}")
    cov = (coverage or {}).get(file)
    if cov is None:
        cov = read_exr(path, layers=[COVERAGE_LAYER])[COVERAGE_LAYER]
    cov = cov[..., None] if cov.ndim == 2 else cov
    bands = len(_field(records[table_key], "channels"))
    return cov, _table(path, table_key, cov, bands)


def _read_missing(
    records: Mapping[str, Any],
    values: dict[str, np.ndarray],
    keys: Sequence[str],
    path_of: Callable[[str], Path],
    coverage: dict[str, np.ndarray] | None = None,
    with_coverage: frozenset[str] = frozenset(),
) -> None:
    """Read the stored layers *keys* into *values*, file by file; and the coverage layer of the
    files in *with_coverage* into *coverage*, in the same decoding."""
    by_file: dict[str, list[str]] = {file: [] for file in with_coverage}
    for key in keys:
        if key not in records:
            raise DatasetError(f"meta.json: a stored-as-factors layer needs {key!r}, not listed")
        by_file.setdefault(str(_field(records[key], "file")), []).append(key)
    for file, names in by_file.items():
        extra = [COVERAGE_LAYER] if file in with_coverage and coverage is not None else []
        layers = [_field(records[k], "exr_layer") for k in names] + extra
        arrays = read_exr(path_of(file), layers=layers)
        values.update({k: arrays[_field(records[k], "exr_layer")] for k in names})
        if extra and coverage is not None:
            coverage[file] = arrays[COVERAGE_LAYER]


def read_layers(
    meta: Mapping[str, Any],
    records: Mapping[str, Any],
    keys: Sequence[str],
    path_of: Callable[[str], Path],
    *,
    verify: bool = True,
) -> dict[str, np.ndarray]:
    """The arrays of the layers *keys* (``meta.json["layers"]`` *records*), the stored ones read
    file by file through *path_of* (each file decoded once), the others rebuilt from their
    factors and, with *verify*, checked against their recorded SHA-256 (one-line
    :class:`DatasetError`); the factors read only for that are not returned."""
    forms = storage_forms(meta, records)
    terms = _terms(meta)
    derived = _closure(keys, forms, terms)
    stored = {k for k in keys if k not in forms}
    for key in derived:
        stored.update(n for n in terms[key] if n not in forms)
    with_coverage = frozenset(
        str(_field(records[k], "file")) for k in derived if forms[k] in BAND_FORMS
    )
    values: dict[str, np.ndarray] = {}
    coverage: dict[str, np.ndarray] = {}
    _read_missing(records, values, sorted(stored), path_of, coverage, with_coverage)
    if derived:
        rebuild_layers(meta, records, values, path_of, wanted=keys, coverage=coverage)
    wrong = rebuilt_mismatches(meta, values) if verify else []
    if wrong:
        raise DatasetError(
            f"layers {wrong} rebuilt from their stored factors do not match their SHA-256 in "
            "meta.json; the sample is damaged (spectrinsic check finds every such layer)"
        )
    return {k: values[k] for k in keys}
