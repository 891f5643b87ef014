"""Dataset samples from generated scenes or scene files (``dataset --generator``/``--scenes``).

A config whose ``source`` is set plans its samples here instead of from the library layout:

* ``{"generator": NAME, "count": N, "views": V, ...}``: scenes ``NAME-00000`` ... each seen
  from V cameras; sample ids ``<scene>__v<view>__<family>``. Every generated scene is saved as
  a YAML scene file (``FORMAT.md``) in ``<out>/scenes/<sample id>.yaml``, so it can be edited
  and re-rendered with ``dataset --scenes``.
* ``{"scenes": [{"path": ..., "sha256": ...}], "materials": {...}, "default_spectrum": ...}``:
  one sample ``<stem>__v0__file`` per scene file; the files' SHA-256 are part of the config, so
  editing a scene file asks for ``--rebuild``.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from spectrinsic.errors import DatasetError, SceneError, validate_choice
from spectrinsic.gt_export.sample import file_sha256
from spectrinsic.pipeline.presets import DatasetConfig
from spectrinsic.pipeline.tasks import SampleTask
from spectrinsic.scenes.generators import (
    GENERATORS,
    GeneratorOptions,
    MaterialDistribution,
    generated_family,
    generated_scene_name,
)
from spectrinsic.scenes.generators.lights import check_saturation
from spectrinsic.scenes.generators.materials import check_ranges
from spectrinsic.scenes.sample_id import SampleId
from spectrinsic.scenes.scene_writer import save_scene
from spectrinsic.scenes.sources import FileSource, GeneratedSource, scene_file_kind
from spectrinsic.spectra import list_spectra

__all__ = ["SCENES_FOLDER", "generator_source", "files_source", "plan_source_samples", "save_generated"]

#: Folder of a dataset holding the generated scenes' YAML files.
SCENES_FOLDER = "scenes"
_SAFE = re.compile(r"[^A-Za-z0-9._-]+")
#: Most generated scenes and cameras per scene in one dataset: planning is O(count x views)
#: before the first render, and 10^5 scenes already take days to render on a workstation.
MAX_COUNT = 100_000
#: Version of what the generators draw for a seed, part of the config: a set built by an older
#: version (other light pools, furniture, framing) asks for ``--rebuild`` instead of mixing.
#: 2: saturated lights, ranges obeyed by every material, framed rooms (issue 22).
GENERATOR_VERSION = 2
MAX_VIEWS = 64


def generator_source(generator: str, count: int, *, views: int = 1,
                     value_range: Sequence[float] = (2.0, 9.0),
                     chroma_range: Sequence[float] = (0.0, 16.0),
                     min_coverage: float = 0.15, sfu: bool = False,
                     light_saturation: Sequence[float] | None = None) -> str:
    """The canonical ``source`` JSON of a generated set (validated: an impossible range is
    refused here, before any scene is planned)."""
    validate_choice(generator, GENERATORS, "scene generator", error=DatasetError)
    try:
        check_ranges((float(value_range[0]), float(value_range[1])),
                     (float(chroma_range[0]), float(chroma_range[1])))
    except SceneError as exc:
        raise DatasetError(f"--value-range / --chroma-range: {exc}") from None
    try:
        if light_saturation is not None:
            check_saturation((float(light_saturation[0]), float(light_saturation[1])))
    except SceneError as exc:
        raise DatasetError(f"--light-saturation: {exc}") from None
    if not (1 <= count <= MAX_COUNT and 1 <= views <= MAX_VIEWS):
        raise DatasetError(f"--count {count} / --views {views}; expected whole numbers from 1 to "
                           f"{MAX_COUNT} scenes and 1 to {MAX_VIEWS} views")
    spec = {"generator": generator, "count": int(count), "views": int(views),
            "value_range": [float(v) for v in value_range],
            "chroma_range": [float(c) for c in chroma_range],
            "min_coverage": float(min_coverage), "sfu": bool(sfu),
            "generator_version": GENERATOR_VERSION}
    if light_saturation is not None:  # absent when not given: older configs keep their hash
        spec["light_saturation"] = [float(v) for v in light_saturation]
    return json.dumps(spec, sort_keys=True)


def files_source(paths: Sequence[str | os.PathLike[str]], *,
                 materials: Mapping[str, str] | None = None,
                 default_spectrum: str | None = None) -> str:
    """The canonical ``source`` JSON of a set of scene files (each must exist)."""
    entries = []
    for p in paths:
        path = Path(p).resolve()
        if not path.is_file():
            raise DatasetError(f"--scenes {str(p)!r}: no such file")
        scene_file_kind(path)
        entries.append({"path": str(path), "sha256": file_sha256(path)})
    stems = [_SAFE.sub("-", Path(e["path"]).stem) for e in entries]
    dupes = sorted({s for s in stems if stems.count(s) > 1})
    if dupes:
        raise DatasetError(f"--scenes: several files named {dupes}; scene names must be unique")
    spec = {"scenes": entries, "materials": dict(sorted((materials or {}).items())),
            "default_spectrum": default_spectrum}
    return json.dumps(spec, sort_keys=True)


def _generator_options(spec: Mapping[str, Any], config: DatasetConfig, data_dir: str | None) -> Any:
    sfu_r: tuple[str, ...] = ()
    sfu_i: tuple[str, ...] = ()
    if spec.get("sfu"):
        try:
            sfu_r = tuple(list_spectra("sfu", data_dir=data_dir))
            sfu_i = tuple(list_spectra("sfu-illum", data_dir=data_dir))
        except Exception as exc:  # noqa: BLE001 - any data-directory failure reads the same
            raise DatasetError(f"--sfu needs the SFU data directory (--data-dir): {exc}") from exc
    dist = MaterialDistribution(tuple(spec["value_range"]), tuple(spec["chroma_range"]),
                                sfu_fraction=0.5 if sfu_r else 0.0)
    saturation = spec.get("light_saturation")
    return GeneratorOptions(width=config.width, height=config.height, views=int(spec["views"]),
                            materials=dist, min_coverage=float(spec["min_coverage"]),
                            sfu_reflectances=sfu_r, sfu_illuminants=sfu_i,
                            light_saturation=None if saturation is None else tuple(saturation))


def plan_source_samples(out: str, config: DatasetConfig, *, data_dir: str | None,
                        render_threads: int | None) -> list[SampleTask]:
    """The :class:`~spectrinsic.pipeline.tasks.SampleTask` list of ``config.source``."""
    spec = json.loads(config.source or "{}")
    rows: list[tuple[str, int, str, Any]] = []
    if "generator" in spec:
        gen, options = spec["generator"], _generator_options(spec, config, data_dir)
        for i in range(int(spec["count"])):
            name, family = generated_scene_name(gen, i), generated_family(config.seed, gen, i)
            rows += [(name, v, family, GeneratedSource(gen, config.seed, i, v, options))
                     for v in range(options.views)]
    else:
        materials = tuple(sorted(spec.get("materials", {}).items()))
        for entry in spec["scenes"]:
            name = _SAFE.sub("-", Path(entry["path"]).stem)
            rows.append((name, 0, "file", FileSource(entry["path"], config.width, config.height,
                                                     materials, spec.get("default_spectrum"))))
    return [SampleTask.planned(SampleId(name, v, cond), config, out, data_dir=data_dir,
                               render_threads=render_threads, source=src)
            for name, v, cond, src in rows]


def save_generated(out_dir: str | os.PathLike[str], sample_id: str, scene: Any) -> Path:
    """Write a generated scene as ``<out>/scenes/<sample id>.yaml`` (meshes beside it)."""
    folder = Path(out_dir) / SCENES_FOLDER
    folder.mkdir(parents=True, exist_ok=True)
    return save_scene(scene, folder / f"{sample_id}.yaml")
