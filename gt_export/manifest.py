"""``manifest.json``: a dataset's settings, provenance, splits, noise summary and file hashes.

Written when a build finishes (and rewritten by every resumed build): the hash of every file of
every sample (paths relative to the dataset folder), train/val/test splits made by scene, and
the median noise figures. Nothing time-dependent is recorded, so the same build gives the same
manifest.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from spectrinsic.data_dir import resolve_data_dir
from spectrinsic.errors import DatasetError, SampleMetaError
from spectrinsic.gt_export.integrity import guarded_write
from spectrinsic.gt_export.json_fields import JsonFields, load_json
from spectrinsic.gt_export.sample import (
    FORMAT_VERSION,
    MANIFEST_NAME,
    TMP_PREFIX,
    canonical_json,
    config_hash,
    confined_path,
    file_sha256,
    plain_data,
    sample_dirs,
)
from spectrinsic.gt_export.sample_meta import SampleMeta, read_meta
from spectrinsic.provenance import software_versions
from spectrinsic.rng import seed_from_key

__all__ = [
    "SPLIT_FRACTIONS",
    "write_manifest",
    "ManifestRecord",
    "read_manifest",
    "read_splits",
    "split_of",
    "splits_by_scene",
    "noise_summary",
    "variants_of",
]

#: Train / val / test shares of the scenes (each scene's samples go to one split).
SPLIT_FRACTIONS: tuple[tuple[str, float], ...] = (("train", 0.8), ("val", 0.1), ("test", 0.1))


def _spectral_provenance(metas: Sequence[SampleMeta], data_dir: Any) -> dict[str, Any]:
    used: set[str] = set()
    for meta in metas:
        used.update(meta.materials.values())
        used.update(light.spectrum for light in meta.lights)
        used.update(f"camera:{c}" for c in meta.cameras)
        if meta.cube_sensors:
            used.add(meta.cube_sensors)
    versions = software_versions()
    out: dict[str, Any] = {
        "spectra_used": sorted(used),
        "munsell": f"Munsell1269.dat from luxpy {versions['luxpy']} (Parkkinen et al. 1989)",
        "cie_and_cameras": f"colour-science {versions['colour-science']} (CIE 1931 2°, "
        "CIE illuminants, NPL camera sensitivities)",
        "ground_truth_grid": "360-830 nm at 1 nm",
    }
    root = resolve_data_dir(data_dir)
    if root is not None and (root / "PROVENANCE.md").is_file():
        out["data_directory_provenance_sha256"] = file_sha256(root / "PROVENANCE.md")
    return out


def _sample_files(sample: Path) -> list[Path]:
    return sorted(p for p in sample.rglob("*") if p.is_file())


def write_manifest(
    dataset_dir: str | os.PathLike[str],
    config: Mapping[str, Any],
    *,
    data_dir: str | os.PathLike[str] | None = None,
) -> Path:
    """Write ``manifest.json``: settings, seed, versions, variants, provenance, SHA-256 per file.

    Every file inside every sample folder is hashed (paths relative to the dataset folder).
    Nothing time-dependent is recorded, so the same build gives the same manifest.
    """
    root = Path(dataset_dir)
    samples = sample_dirs(root)
    metas = [read_meta(s) for s in samples]
    manifest = {
        "format_version": FORMAT_VERSION,
        "config": config,
        "config_hash": config_hash(config),
        "seed": config.get("seed"),
        "versions": software_versions(),
        "mitsuba_variants": variants_of(metas),
        "spectral_data": _spectral_provenance(metas, data_dir),
        "n_samples": len(samples),
        "noise": noise_summary(metas),
        "split_by": "scene",
        "split_fractions": dict(SPLIT_FRACTIONS),
        "splits": splits_by_scene({m.sample_id: m.scene for m in metas}),
        "samples": {
            s.name: {
                "config_hash": m.config_hash,
                "scene": m.scene,
                "seed": m.seed,
                "files": {p.relative_to(root).as_posix(): file_sha256(p) for p in _sample_files(s)},
            }
            for s, m in zip(samples, metas, strict=True)
        },
    }
    path = root / MANIFEST_NAME
    tmp = path.with_name(f"{TMP_PREFIX}{MANIFEST_NAME}")
    with guarded_write(tmp):
        tmp.write_text(canonical_json(plain_data(manifest)), encoding="utf-8")
    tmp.replace(path)
    return path


def read_splits(dataset_dir: str | os.PathLike[str]) -> dict[str, list[str]]:
    """``{split: [sample ids]}`` of a built dataset's manifest."""
    try:
        record = read_manifest(dataset_dir)
    except SampleMetaError as exc:
        raise DatasetError(f"{exc}; rebuild the dataset") from exc
    if record is None or "splits" not in record.raw:
        raise DatasetError(f"{dataset_dir}: {MANIFEST_NAME} has no splits; rebuild the dataset")
    return record.splits


def variants_of(metas: Sequence[SampleMeta]) -> list[str]:
    """Every Mitsuba variant the samples were rendered with, sorted."""
    return sorted({v for m in metas for v in m.variants})


def split_of(scene: str) -> str:
    """The split of scene *scene*: its ``seed_from_key(0, "split:" + scene)`` as a fraction of
    2³² against the cumulative :data:`SPLIT_FRACTIONS`. It depends on the scene name only, so a
    scene keeps its split when the set grows and all its views and conditions share it.

    >>> split_of("room-living") == split_of("room-living")
    True
    """
    u = seed_from_key(0, f"split:{scene}") / 2**32
    edge = 0.0
    for name, share in SPLIT_FRACTIONS:
        edge += share
        if u < edge:
            return name
    return SPLIT_FRACTIONS[-1][0]


def splits_by_scene(sample_scenes: Mapping[str, str]) -> dict[str, list[str]]:
    """``{split: [sample ids]}`` from ``{sample id: scene name}``, made by scene (no scene in two
    splits, so no view or condition of a scene leaks across)."""
    out: dict[str, list[str]] = {name: [] for name, _ in SPLIT_FRACTIONS}
    for sample, scene in sorted(sample_scenes.items()):
        out[split_of(scene)].append(sample)
    return out


def noise_summary(metas: Sequence[SampleMeta]) -> dict[str, Any]:
    """Median over samples of each sample's median and p95 relative standard error, per layer
    and scene kind (``object``/``complex``), and the worst sample's median."""
    out: dict[str, Any] = {}
    for meta in metas:
        kind = meta.scene_metadata.get("kind", "all")
        for layer, fig in meta.noise.items():
            row = (fig.median, fig.p95, fig.rms, meta.sample_id)
            out.setdefault(layer, {}).setdefault(kind, []).append(row)
    summary: dict[str, Any] = {}
    for layer, kinds in out.items():
        for kind, rows in kinds.items():
            worst = max(rows)
            summary.setdefault(layer, {})[kind] = {
                "samples": len(rows),
                "median_of_medians": float(np.median([r[0] for r in rows])),
                "median_of_p95": float(np.median([r[1] for r in rows])),
                "median_of_rms": float(np.median([r[2] for r in rows])),
                "worst_median": float(worst[0]),
                "worst_sample": worst[3],
            }
    return summary


# ----------------------------------------------------------------------------------------------
# Reading


@dataclass(frozen=True)
class ManifestRecord:
    """The parts of ``manifest.json`` that readers use; :attr:`raw` is the parsed object."""

    path: Path
    config_hash: str | None
    #: ``{split: [sample ids]}`` (empty for a manifest without splits).
    splits: dict[str, list[str]]
    #: Per listed sample: its config hash (``None`` if not recorded) and ``{path: SHA-256}``,
    #: paths relative to the dataset folder and inside the sample's folder.
    sample_hashes: Mapping[str, str | None]
    sample_files: Mapping[str, Mapping[str, str]]
    raw: Mapping[str, Any] = field(repr=False)


def _manifest_samples(
    f: JsonFields, root: Path, listed: Mapping[str, Any]
) -> dict[str, dict[str, str]]:
    out = {}
    for name, record in listed.items():
        files = record.get("files", {}) if isinstance(record, dict) else None
        if not isinstance(files, dict):
            raise f.fail(f"samples.{name}", "an object with a 'files' object", record)
        for rel, digest in files.items():
            inside = rel.startswith(f"{name}/") and confined_path(root / name, rel[len(name) + 1 :])
            if not inside:
                raise f.fail(f"samples.{name}.files", f"paths inside {name}/", rel)
            f.text(digest, f"samples.{name}.files.{rel}")
        out[name] = dict(files)
    return out


def read_manifest(dataset_dir: str | os.PathLike[str]) -> ManifestRecord | None:
    """Read and validate ``<dataset_dir>/manifest.json``; ``None`` if there is none.

    Raises
    ------
    SampleMetaError
        Not JSON, or not shaped like spectrinsic's manifest: one line naming the field.
    """
    root = Path(dataset_dir)
    path = root / MANIFEST_NAME
    if not path.is_file():
        return None
    f = JsonFields(path)
    manifest = f.mapping(load_json(path), "top level")
    listed = f.mapping(manifest.get("samples", {}), "samples")
    files = _manifest_samples(f, root, listed)
    splits = {}
    for split, ids in f.mapping(manifest.get("splits", {}), "splits").items():
        splits[split] = list(f.texts(ids, f"splits.{split}"))
    chash = manifest.get("config_hash")
    return ManifestRecord(
        path=path,
        config_hash=f.text(chash, "config_hash", optional=True),
        splits=splits,
        sample_hashes=MappingProxyType({k: v.get("config_hash", chash) for k, v in listed.items()}),
        sample_files=MappingProxyType(files),
        raw=MappingProxyType(manifest),
    )
