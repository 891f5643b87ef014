"""Verification of a built dataset (``spectrinsic check DIR``).

Checks, per sample: ``meta.json`` readable; every listed file present; every layer readable
with the recorded shape; no NaN or Inf anywhere; no negative values in layers marked
non-negative; ids integral and >= -1; mask 0/1; every identity ``meta.json`` records,
``image = reflectance ∘ shading + residual`` per sensor space, and
``image = reflectance ∘ shading_ratio`` wherever reflectance is non-zero; every file matching
the SHA-256 its ``meta.json`` records. Per dataset: ``manifest.json`` present, its samples
present, every sample built with the manifest's config hash, and the SHA-256 of every file
matching. Noise: :func:`noise_report` lists the samples whose measured noise exceeds a threshold.

A ``meta.json`` or ``manifest.json`` that does not have spectrinsic's structure (a manifest that is
not an object, a layer record without ``file``, a misspelt field, a file entry leading outside its
sample folder) cannot be checked at all: that raises a one-line
:class:`~spectrinsic.errors.SampleMetaError` naming the file and the field. A ``meta.json``
edited after it was written (its seal does not match) is a problem of its sample; the rest of
the sample is still checked.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ..formats.exr import read_exr
from ..layers import REFLECTANCE_FLOOR
from ..layers.spectral_intrinsics import rgb_residual_share
from ..sample import MANIFEST_NAME, META_NAME, SEAL_KEY, TMP_PREFIX, file_sha256, sample_dirs
from ..sample.layer_storage import (
    COVERAGE_LAYER,
    rebuild_layers,
    rebuilt_mismatches,
    storage_forms,
)
from ..sample.meta import Identity, LayerRecord, SampleMeta, read_meta
from .manifest import ManifestRecord, read_manifest

__all__ = [
    "residual_share_problems",
    "check_dataset",
    "check_sample",
    "noise_report",
    "IDENTITY_RTOL",
    "identity_scale",
    "NOISE_THRESHOLD",
    "NOISY",
    "TARGET_MISSED",
]

#: Default flag of :func:`noise_report`: a sample whose raw shading has a median relative
#: standard error above this is called noisy. Advisory: a preset promises no noise level
#: unless its config sets ``noise_target`` (``spectrinsic check`` fails on it only when asked).
NOISE_THRESHOLD = 0.25
#: Marks of :func:`noise_report` lines: above the threshold; the config's ``noise_target``
#: (adaptive sampling, recorded in ``meta.json["render"]["noise_target"]``) not reached.
NOISY, TARGET_MISSED = "NOISY", "TARGET MISSED"

#: Relative tolerance of ``image = reflectance ∘ shading (+ residual + specular)``, relative to
#: the sum of the magnitudes of the terms (:func:`identity_scale`): float32 storage rounds each
#: stored term once (≤ 0.5 ulp each, the residual computed from the others' stored values) and
#: the product once more, so 4 float32 epsilons of that sum is generous yet tight. Where large
#: terms cancel (a strong specular or residual under a dark image) the error is a fraction of
#: the large terms, not of the small image: a tolerance relative to the image alone failed
#: relit samples under LEDs (2.99e-05 against 4.8e-07).
IDENTITY_RTOL = 4 * float(np.finfo(np.float32).eps)


def identity_scale(image: np.ndarray, product: np.ndarray, *terms: np.ndarray) -> np.ndarray:
    """``|image| + |reflectance ∘ shading| + Σ |term|``: the magnitude the rounding of a sum of
    float32 terms is relative to (per channel value, same units as the image)."""
    scale = np.abs(np.asarray(image, np.float64)) + np.abs(product)
    for term in terms:
        scale = scale + np.abs(np.asarray(term, np.float64))
    return scale


def _identity_problem(
    image: np.ndarray,
    refl: np.ndarray,
    shad: np.ndarray,
    *terms: np.ndarray,
    names: str = "image != reflectance * shading",
) -> str | None:
    """``image = refl ∘ shad (+ terms)`` to float32 rounding of the terms' magnitudes
    (:data:`IDENTITY_RTOL`), where reflectance is non-zero (everywhere when terms are given)."""
    valid = np.ones(image.shape, bool) if terms else np.abs(refl) > REFLECTANCE_FLOOR
    if not valid.any():
        return None
    product = refl.astype(np.float64) * shad.astype(np.float64)
    rebuilt = product + sum((t.astype(np.float64) for t in terms), np.zeros_like(product))
    err = np.abs(rebuilt - image)[valid]
    scale = identity_scale(image, product, *terms)[valid]
    bad = err > IDENTITY_RTOL * scale + np.finfo(np.float32).tiny
    if bad.any():
        worst = float((err / np.maximum(scale, np.finfo(np.float32).tiny)).max())
        return (
            f"{names} at {int(bad.sum())} channel values (worst error {worst:.2e} of the "
            f"terms' summed magnitude, tolerance {IDENTITY_RTOL:.1e})"
        )
    return None


def _identity_problems(
    identities: tuple[Identity, ...], data: Mapping[str, np.ndarray]
) -> list[str]:
    out = []
    for ident in identities:
        keys = [ident.image, ident.reflectance, ident.shading, ident.residual]
        keys += [ident.specular] if ident.specular else []
        missing = [k for k in keys if k not in data]
        if missing:
            out.append(f"identity {keys}: layer(s) {missing} missing")
            continue
        # the specular layer, where there is one, is one more term beside the residual
        issue = _identity_problem(
            data[keys[0]],
            data[keys[1]],
            data[keys[2]],
            *(data[k] for k in keys[3:]),
            names=f"{keys[0]} != {keys[1]} * {keys[2]} + " + " + ".join(keys[3:]),
        )
        if issue:
            out.append(f"{keys[0]}: {issue}")
    if all(k in data for k in ("image", "reflectance", "shading_ratio")):
        issue = _identity_problem(
            data["image"],
            data["reflectance"],
            data["shading_ratio"],
            names="image != reflectance * shading_ratio",
        )
        if issue:
            out.append(f"image: {issue}")
    return out


def _rebuilt_problems(meta: SampleMeta, data: Mapping[str, np.ndarray]) -> list[str]:
    """Layers rebuilt from their stored factors that are not the layers the writer computed
    (their SHA-256 in ``meta.json["storage"]``). A residual rebuilt from its identity's terms
    satisfies the identity by construction, so a wrong term shows here, named as the identity."""
    wrong = set(rebuilt_mismatches(meta.raw, data))
    out = []
    for ident in meta.identities:
        if ident.residual in wrong:
            wrong.discard(ident.residual)
            terms = " + ".join(t for t in (ident.specular, ident.residual) if t)
            out.append(
                f"{ident.image}: {ident.image} != {ident.reflectance} * {ident.shading} + "
                f"{terms}: the residual rebuilt from the stored terms is not the one written "
                "(its SHA-256 in meta.json)"
            )
    out += [
        f"layer {k!r} rebuilt from its stored factors does not match its SHA-256 in meta.json"
        for k in sorted(wrong)
    ]
    return out


def _layer_problems(key: str, rec: LayerRecord, data: np.ndarray) -> list[str]:
    out = []
    if data.shape != rec.shape:
        out.append(f"layer {key!r} has shape {data.shape}, meta.json says {rec.shape}")
    finite = np.isfinite(data)
    if not finite.all():
        nan, inf = int(np.isnan(data).sum()), int(np.isinf(data).sum())
        out.append(f"layer {key!r} has {nan} NaN and {inf} Inf values")
    if rec.nonnegative and (data[finite] < 0).any():
        out.append(f"layer {key!r} has {int((data[finite] < 0).sum())} negative values")
    if key in ("material_id", "object_id", "semantic"):
        if (data[finite] != np.rint(data[finite])).any() or (data[finite] < -1).any():
            out.append(f"layer {key!r} holds values that are not integer ids >= -1")
    if key == "mask" and not np.isin(data[finite], (0.0, 1.0)).all():
        out.append("layer 'mask' holds values other than 0 and 1")
    return out


def _file_problems(meta: SampleMeta) -> list[str]:
    """Listed files missing, or not matching the SHA-256 that ``meta.json`` records."""
    problems = []
    if meta.sealed is False:
        problems.append(
            f"{META_NAME} does not match its seal ({SEAL_KEY}): edited or damaged "
            "after it was written"
        )
    for rel in meta.files:
        if not (meta.folder / rel).is_file():
            problems.append(f"file {rel!r} listed in meta.json is missing")
        elif file_sha256(meta.folder / rel) != meta.hashes[rel]:
            problems.append(f"file {rel!r} does not match its SHA-256 in {META_NAME}")
    return problems


def _layer_data(meta: SampleMeta, problems: list[str]) -> dict[str, np.ndarray]:
    """Every layer's array (read file by file); unreadable files and layers go to *problems*."""
    data: dict[str, np.ndarray] = {}
    by_file: dict[str, list[str]] = {}
    coverage: dict[str, np.ndarray] = {}
    try:
        forms = storage_forms(meta.raw, meta.layers)
    except DatasetError as exc:
        problems.append(str(exc))
        return data
    for key, rec in meta.layers.items():
        if key not in forms:  # stored as its factors: rebuilt below
            by_file.setdefault(rec.file, []).append(key)
    for file, keys in by_file.items():
        try:
            arrays = read_exr(meta.folder / file)
        except DatasetError as exc:
            problems.append(str(exc).replace(str(meta.folder) + os.sep, ""))
            continue
        if COVERAGE_LAYER in arrays:  # the factor of a layer stored as coverage @ table
            coverage[file] = arrays[COVERAGE_LAYER]
        for key in keys:
            exr_layer = meta.layers[key].exr_layer
            if exr_layer not in arrays:
                problems.append(f"layer {key!r} is missing from {file}")
                continue
            data[key] = arrays[exr_layer]
            problems.extend(_layer_problems(key, meta.layers[key], data[key]))
    if forms:
        try:
            rebuild_layers(
                meta.raw, meta.layers, data, lambda file: meta.folder / file, coverage=coverage
            )
        except DatasetError as exc:
            problems.append(str(exc).replace(str(meta.folder) + os.sep, ""))
            return data
        for key in forms:
            problems.extend(_layer_problems(key, meta.layers[key], data[key]))
    return data


def _semantic_problems(meta: Mapping[str, Any], data: Mapping[str, np.ndarray]) -> list[str]:
    """The ``semantic`` layer's ids are in the class table (``semantic_classes``), and each
    object of the ``object_id`` layer has one class."""
    if "semantic" not in data:
        return []
    table = meta.get("semantic_classes")
    if not table:
        return ["layer 'semantic' has no class table (semantic_classes) in meta.json"]
    ids = np.rint(data["semantic"]).astype(np.int64)
    unknown = sorted({int(v) for v in np.unique(ids)} - {-1} - {int(k) for k in table})
    out = [f"layer 'semantic' holds ids {unknown} not in semantic_classes"] if unknown else []
    if "object_id" in data:
        objects = np.rint(data["object_id"]).astype(np.int64)
        pairs = np.unique(np.stack([objects.ravel(), ids.ravel()]), axis=1)
        split = np.unique(pairs[0], return_counts=True)
        mixed = split[0][split[1] > 1].tolist()
        if mixed:
            out.append(f"layer 'semantic': objects {mixed} have more than one class")
    return out


def check_sample(sample: str | os.PathLike[str]) -> list[str]:
    """Problems of one sample folder (empty list: fine). Messages do not repeat the sample id.

    Raises
    ------
    DatasetError
        (:class:`~spectrinsic.errors.SampleMetaError`) If ``meta.json`` is not JSON or not
        shaped like spectrinsic's (see the module notes).
    """
    sample = Path(sample)
    if not (sample / META_NAME).is_file():
        return [f"{META_NAME} is missing"]
    meta = read_meta(sample, verify=False)  # the seal is reported below, with everything else
    problems = _file_problems(meta)
    for required in ("image", "reflectance", "shading", "illuminant"):
        if required not in meta.layers:
            problems.append(f"layer {required!r} is missing from meta.json")
    data = _layer_data(meta, problems)
    if not meta.identities:
        problems.append(
            "meta.json records no identities (image = reflectance * shading + residual)"
        )
    problems.extend(_identity_problems(meta.identities, data))
    problems.extend(_rebuilt_problems(meta, data))
    problems.extend(_semantic_problems(meta.raw, data))
    return problems


def check_dataset(
    dataset_dir: str | os.PathLike[str], *, progress: Callable[[str], None] | None = None
) -> list[str]:
    """Verify a built dataset; return one line per problem (empty list: the set is sound).

    Lines start with the sample id (or ``"<dataset>"`` for set-wide problems). *progress*, if
    given, is called with each sample id once that sample is checked.
    """
    root = Path(dataset_dir)
    if not root.is_dir():
        return [f"<dataset>: folder {str(root)!r} does not exist"]
    # a manifest of the wrong shape stops the check before the (slow) per-sample checks
    manifest = read_manifest(root)
    problems: list[str] = []
    samples = sample_dirs(root)
    if not samples:
        problems.append("<dataset>: no sample folders with meta.json")
    for leftover in sorted(root.glob(f"{TMP_PREFIX}*")):
        problems.append(
            f"<dataset>: leftover temporary {leftover.name!r} from an interrupted write"
        )
    for sample in samples:
        problems.extend(f"{sample.name}: {p}" for p in check_sample(sample))
        if progress is not None:
            progress(sample.name)
    if manifest is None:
        return [*problems, f"<dataset>: {MANIFEST_NAME} is missing"]
    problems.extend(_config_problems(manifest, samples))
    problems.extend(_manifest_problems(root, manifest, samples))
    return problems


def _config_problems(manifest: ManifestRecord, samples: list[Path]) -> list[str]:
    """Samples whose config hash (in ``meta.json`` or the manifest) is not the dataset's."""
    expected = manifest.config_hash
    problems = []
    for sample in samples:
        own = read_meta(sample, verify=False).config_hash
        if own != expected:
            problems.append(
                f"{sample.name}: built with config hash {str(own)[:12]}, but "
                f"{MANIFEST_NAME} describes config hash {str(expected)[:12]}"
            )
        recorded = manifest.sample_hashes.get(sample.name, expected)
        if recorded != expected:
            problems.append(
                f"{sample.name}: {MANIFEST_NAME} lists it with config hash "
                f"{str(recorded)[:12]}, not the dataset's {str(expected)[:12]}"
            )
    return problems


def _manifest_problems(root: Path, manifest: ManifestRecord, samples: list[Path]) -> list[str]:
    """Samples missing from the manifest or the disk, and files not matching their SHA-256."""
    problems = []
    listed = manifest.sample_files
    on_disk = {s.name for s in samples}
    for name in sorted(set(listed) - on_disk):
        problems.append(f"{name}: listed in {MANIFEST_NAME} but missing or incomplete")
    for name in sorted(on_disk - set(listed)):
        problems.append(f"{name}: present but not listed in {MANIFEST_NAME}")
    for name in sorted(set(listed) & on_disk):
        expected = listed[name]
        actual = {p.relative_to(root).as_posix() for p in (root / name).rglob("*") if p.is_file()}
        for rel in sorted(actual - set(expected)):
            problems.append(f"{name}: file {rel!r} is not in {MANIFEST_NAME}")
        for rel, digest in sorted(expected.items()):
            path = root / rel
            if not path.is_file():
                problems.append(f"{name}: file {rel!r} from {MANIFEST_NAME} is missing")
            elif file_sha256(path) != digest:
                problems.append(
                    f"{name}: file {rel!r} does not match its SHA-256 in {MANIFEST_NAME}"
                )
    return problems


def noise_report(
    dataset_dir: str | os.PathLike[str], *, threshold: float = NOISE_THRESHOLD
) -> tuple[list[str], list[str]]:
    """Per-sample noise lines and the samples flagged as too noisy.

    Returns ``(lines, flagged)``: one line per sample with the median and p95 relative standard
    error of each measured layer (``meta.json["noise"]``), and the ids whose raw shading median
    exceeds *threshold*. A line holds :data:`NOISY` for a flagged sample and
    :data:`TARGET_MISSED` where the build promised a noise target its image did not reach.
    """
    lines, flagged = [], []
    for sample in sample_dirs(Path(dataset_dir)):
        meta = read_meta(sample, verify=False)
        figures, missed = meta.noise, _missed_target(meta.raw.get("render"))
        if not figures:
            lines.append(f"{sample.name}: no noise estimate (one batch)" + missed)
            continue
        parts = [
            f"{k} median {100 * v.median:.1f} % p95 {100 * v.p95:.1f} %"
            for k, v in sorted(figures.items())
        ]
        shading = figures["shading_raw"].median if "shading_raw" in figures else 0.0
        if shading > threshold:
            flagged.append(sample.name)
            parts.append(f"{NOISY} (shading median above {100 * threshold:.0f} %)")
        lines.append(f"{sample.name}: " + "; ".join(parts) + missed)
    return lines, flagged


def _missed_target(render: object) -> str:
    """``"; TARGET MISSED (...)"`` when the recorded ``noise_target`` (the build's promise of a
    median relative standard error of the image) was not reached, else ``""``."""
    record = render.get("noise_target") if isinstance(render, Mapping) else None
    if not isinstance(record, Mapping):
        return ""
    target, reached = record.get("target"), record.get("reached")
    if (
        not isinstance(target, int | float)
        or not isinstance(reached, int | float)
        or reached <= target
    ):
        return ""
    return (
        f"; {TARGET_MISSED} (image median {100 * reached:.1f} % above the config's "
        f"noise_target {100 * target:.1f} % after {record.get('max_batches')} batches)"
    )


def residual_share_problems(dataset_dir: str | os.PathLike[str], limit: float) -> list[str]:
    """``"<sample>: ..."`` for each sample whose RGB residual share (``Σ|residual| / Σ|image|``
    over the mask, ``meta.json["residual_share"]``) is above *limit* or not recorded."""
    found = (sample_share_problem(sample, limit) for sample in sample_dirs(Path(dataset_dir)))
    return [problem for problem in found if problem is not None]


def sample_share_problem(sample: Path, limit: float) -> str | None:
    """The residual-share problem of one sample folder (see :func:`residual_share_problems`)."""
    meta = read_meta(sample, verify=False).raw
    share = rgb_residual_share(meta)
    spectral = (meta.get("residual_share") or {}).get("image_bands")
    per_band = "" if spectral is None else f"; per band {100 * spectral:.3g} %"
    if share is None:
        return f"{sample.name}: records no residual share (built before it existed)"
    if share > limit:
        return (
            f"{sample.name}: residual share {100 * share:.3g} % of the image above "
            f"--max-residual-share {limit:g}{per_band}"
        )
    return None
