"""``manifest.json``: a dataset's settings, provenance, splits, noise summary and file hashes.

Written when a build finishes (and rewritten by every resumed build): the hash of every file of
every sample (paths relative to the dataset folder), train/val/test splits made by scene, and
the median noise figures. Nothing time-dependent is recorded, so the same build gives the same
manifest (the build's time is in ``build-time.json``, :mod:`.build_time`).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from ...data_dir import resolve_data_dir
from ...errors import DatasetError, SampleMetaError
from ...file_writes import write_text_file
from ...provenance import software_versions
from ...rng import seed_from_key
from ...scenes.material_labels import label_spectrum
from ..formats.exr import DEFAULT_COMPRESSION
from ..layers.spectral_intrinsics import residual_summary
from ..sample import (
    FORMAT_VERSION,
    MANIFEST_NAME,
    canonical_json,
    config_hash,
    confined_path,
    file_sha256,
    plain_data,
    sample_dirs,
)
from ..sample.json_fields import JsonFields, load_json
from ..sample.layer_storage import storage_summary
from ..sample.meta import SampleMeta, read_meta
from ..sample.stored_layers import PIZ_FILES
from ..sample.transport_exr import COMPACT_LAYOUT, TRANSPORT_COMPRESSION, TRANSPORT_NAME
from ..sample.working_view import space_of

__all__ = [
    "SPLIT_FRACTIONS",
    "write_manifest",
    "ManifestRecord",
    "read_manifest",
    "read_splits",
    "SplitFractions",
    "check_split_fractions",
    "split_counts",
    "splits_by_scene",
    "noise_summary",
    "variants_of",
    "working_spaces",
]

#: ``(split name, share of the scenes)`` pairs, in the order the splits are filled.
SplitFractions = tuple[tuple[str, float], ...]

#: Train / val / test shares of the scenes (each scene's samples go to one split); a build
#: takes others from ``dataset --split-fractions`` (``DatasetConfig.split_fractions``).
SPLIT_FRACTIONS: SplitFractions = (("train", 0.8), ("val", 0.1), ("test", 0.1))


def _spectral_provenance(metas: Sequence[SampleMeta], data_dir: Any) -> dict[str, Any]:
    used: set[str] = set()
    for meta in metas:
        used.update(label_spectrum(n) for n in meta.materials.values())
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


def _semantic_classes(metas: Sequence[SampleMeta]) -> dict[str, Any]:
    """``{"semantic_classes": table}`` of the samples with a ``semantic`` layer (one table, as
    every sample of a build records the same), else nothing (samples from before issue 41)."""
    tables = [m.raw["semantic_classes"] for m in metas if "semantic_classes" in m.raw]
    return {"semantic_classes": tables[0]} if tables else {}


def working_spaces(metas: Sequence[SampleMeta]) -> dict[str, dict[str, Any]]:
    """The samples' RGB working spaces by name: colour-science's name, the perfect white's
    colour under D65 (``white_d65``), the sign of the shading (negative channels kept, or set
    to 0 in ``srgb``), and the sample count."""
    out: dict[str, dict[str, Any]] = {}
    for meta in metas:
        space = space_of(meta.raw)
        entry = out.setdefault(
            space.name,
            {
                "colourspace": space.colourspace,
                "white_d65": [round(float(v), 6) for v in space.white],
                "shading": "negative channels set to 0 (into the residual)"
                if space.clip_shading
                else "negative channels kept",
                "samples": 0,
            },
        )
        entry["samples"] += 1
    return out


def _sample_files(sample: Path) -> list[Path]:
    return sorted(p for p in sample.rglob("*") if p.is_file())


def write_manifest(
    dataset_dir: str | os.PathLike[str],
    config: Mapping[str, Any],
    *,
    data_dir: str | os.PathLike[str] | None = None,
    split_fractions: SplitFractions = SPLIT_FRACTIONS,
) -> Path:
    """Write ``manifest.json``: settings, seed, versions, variants, provenance, splits by scene
    (:func:`splits_by_scene` with *split_fractions*), SHA-256 per file.

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
        "residual_share": residual_summary([m.raw for m in metas]),
        "working_space": working_spaces(metas),
        "storage": {
            "exr_compression": {
                "*.exr": DEFAULT_COMPRESSION,
                **{f: "piz" for f in PIZ_FILES},
                TRANSPORT_NAME: TRANSPORT_COMPRESSION,
            },
            "transport_layout": COMPACT_LAYOUT,
            "layers": storage_summary(m.raw for m in metas),
        },
        **_semantic_classes(metas),
        "split_by": "scene",
        "split_fractions": dict(split_fractions),
        "splits": splits_by_scene({m.sample_id: m.scene for m in metas}, split_fractions),
        "samples": {
            s.name: {
                "config_hash": m.config_hash,
                "scene": m.scene,
                "seed": m.seed,
                **(
                    {"residual_share": m.raw["residual_share"]} if "residual_share" in m.raw else {}
                ),
                "files": {p.relative_to(root).as_posix(): file_sha256(p) for p in _sample_files(s)},
            }
            for s, m in zip(samples, metas, strict=True)
        },
    }
    path = root / MANIFEST_NAME
    write_text_file(path, canonical_json(plain_data(manifest)))
    return path


def read_splits(
    dataset_dir: str | os.PathLike[str], split: str | None = None
) -> dict[str, list[str]]:
    """``{split: [sample ids]}`` of a built dataset's manifest.

    With *split*, that split must exist and hold a sample: an unknown name or an empty split
    (fewer scenes than splits) is a one-line :class:`~spectrinsic.errors.DatasetError` naming
    the split and the dataset's scene count.
    """
    try:
        record = read_manifest(dataset_dir)
    except SampleMetaError as exc:
        raise DatasetError(f"{exc}; rebuild the dataset") from exc
    if record is None:
        raise DatasetError(f"{dataset_dir}: no {MANIFEST_NAME}; expected a built dataset folder")
    if "splits" not in record.raw:
        raise DatasetError(f"{dataset_dir}: {MANIFEST_NAME} has no splits; rebuild the dataset")
    if split is not None and split not in record.splits:
        raise DatasetError(f"split {split!r}; expected one of {sorted(record.splits)}")
    if split is not None and not record.splits[split]:
        n = record.n_scenes
        raise DatasetError(
            f"split {split!r} of {dataset_dir} is empty: the dataset has {n} scene(s) for "
            f"{len(record.splits)} splits (every split gets a scene from {len(record.splits)} "
            "scenes on; build more scenes or choose other --split-fractions)"
        )
    return record.splits


def variants_of(metas: Sequence[SampleMeta]) -> list[str]:
    """Every Mitsuba variant the samples were rendered with, sorted."""
    return sorted({v for m in metas for v in m.variants})


def _scene_key(scene: str) -> float:
    """Where scene *scene* falls in [0, 1): ``seed_from_key(0, "split:" + scene) / 2³²``. It
    depends on the name only, so the scenes' order (and mostly their splits) hold as a set grows."""
    return seed_from_key(0, f"split:{scene}") / 2**32


def check_split_fractions(fractions: SplitFractions) -> SplitFractions:
    """*fractions* if they are ``(name, share)`` pairs with distinct names and shares > 0 summing
    to 1 (within 1e-6); else a one-line :class:`~spectrinsic.errors.DatasetError`.

    >>> check_split_fractions((("train", 0.5), ("val", 0.5)))
    (('train', 0.5), ('val', 0.5))
    """
    pairs = tuple((str(name), float(share)) for name, share in fractions)
    names = [name for name, _ in pairs]
    shown = ", ".join(f"{n}={v:g}" for n, v in pairs)
    if not pairs or len(set(names)) != len(names) or not all(names):
        raise DatasetError(f"split fractions {shown or '(none)'}; expected distinct named splits")
    if (
        not all(np.isfinite(v) and v > 0 for _, v in pairs)
        or abs(sum(v for _, v in pairs) - 1) > 1e-6
    ):
        raise DatasetError(f"split fractions {shown}; expected shares > 0 that sum to 1")
    return pairs


def split_counts(n_scenes: int, fractions: SplitFractions = SPLIT_FRACTIONS) -> dict[str, int]:
    """Scenes per split for *n_scenes* scenes: the largest-remainder rounding of
    ``share * n_scenes``, then, when there are at least as many scenes as splits, one scene
    moved into each empty split from the largest one, so every split exists.

    >>> split_counts(11)
    {'train': 9, 'val': 1, 'test': 1}
    >>> split_counts(3)
    {'train': 1, 'val': 1, 'test': 1}
    >>> split_counts(2)
    {'train': 2, 'val': 0, 'test': 0}
    """
    pairs = check_split_fractions(fractions)
    exact = [share * n_scenes for _, share in pairs]
    counts = [int(np.floor(x)) for x in exact]
    by_remainder = sorted(range(len(pairs)), key=lambda i: (counts[i] - exact[i], i))
    for i in by_remainder[: n_scenes - sum(counts)]:
        counts[i] += 1
    if n_scenes >= len(pairs):
        for i in range(len(pairs)):
            if counts[i] == 0:
                counts[max(range(len(pairs)), key=lambda j: (counts[j], -j))] -= 1
                counts[i] = 1
    return {name: c for (name, _), c in zip(pairs, counts, strict=True)}


def splits_by_scene(
    sample_scenes: Mapping[str, str], fractions: SplitFractions = SPLIT_FRACTIONS
) -> dict[str, list[str]]:
    """``{split: [sample ids]}`` from ``{sample id: scene name}``, made by scene (no scene in two
    splits, so no view or condition of a scene leaks across).

    The scenes, ordered by :func:`_scene_key`, fill the splits in turn with
    :func:`split_counts` scenes each: with at least as many scenes as splits (3 for
    train/val/test) every split holds a scene.
    """
    scenes = sorted(set(sample_scenes.values()), key=lambda s: (_scene_key(s), s))
    owner: dict[str, str] = {}
    start = 0
    for name, count in split_counts(len(scenes), fractions).items():
        owner.update({scene: name for scene in scenes[start : start + count]})
        start += count
    out: dict[str, list[str]] = {name: [] for name, _ in fractions}
    for sample, scene in sorted(sample_scenes.items()):
        out[owner[scene]].append(sample)
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

    @property
    def n_scenes(self) -> int:
        """Distinct scenes of the listed samples (what the splits were made from)."""
        listed = self.raw.get("samples", {})
        return len({r.get("scene") for r in listed.values() if isinstance(r, dict)})


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
