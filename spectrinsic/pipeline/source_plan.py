"""Dataset samples from generated scenes or scene files (``dataset --generator``/``--scenes``).

A config whose ``source`` is set plans its samples here instead of from the library layout:

* ``{"generator": NAME, "count": N, "views": V, ...}``: scenes ``NAME-00000`` ... each seen
  from V cameras; sample ids ``<scene>__v<view>__<family>``. Every generated scene is saved as
  a YAML scene file (``FORMAT.md``) in ``<out>/scenes/<sample id>.yaml``, so it can be edited
  and re-rendered with ``dataset --scenes``.
* ``{"scenes": [{"path": ..., "sha256": ...}], "materials": {...}, "default_spectrum": ...,
  "resolution": [W, H] or None, "new_sample": bool}``: one sample ``<stem>__v0__file`` per
  scene file, at the file's own camera size unless ``resolution`` is given; the files' SHA-256
  are part of the config, so editing a scene file asks for ``--rebuild``. A scene saved by a
  generated build records its sample (``metadata.sample``: id and seed), and re-rendering it
  reproduces that sample (same id, same seed) unless ``new_sample`` is set.
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ..errors import DatasetError, SceneError, SpectrinsicError, validate_choice
from ..gt_export.sample import file_sha256
from ..path_kinds import file_type
from ..render.algebra.light_transport import diagonal_mode_names
from ..render.band_path.traversal import resolve_integrator
from ..scenes.generators import (
    GENERATORS,
    GeneratorOptions,
    GlossDistribution,
    MaterialDistribution,
    generated_family,
    generated_scene_name,
)
from ..scenes.generators.daylight import FLUX_SHARE
from ..scenes.generators.lights import check_saturation
from ..scenes.generators.materials import check_ranges
from ..scenes.model import Scene
from ..scenes.sample_id import SampleId
from ..scenes.scene_writer import save_scene
from ..scenes.semantic import SemanticRules, rules_from_record
from ..scenes.sources import FileSource, GeneratedSource, scene_file_kind
from ..scenes.yaml_limits import load_yaml_file
from ..spectra import list_spectra
from .presets import DatasetConfig
from .tasks import SampleTask

__all__ = [
    "check_integrator_plan",
    "check_scene_integrator",
    "SCENES_FOLDER",
    "generator_source",
    "files_source",
    "plan_source_samples",
    "save_generated",
    "saved_sample",
    "file_sample",
    "semantic_rules",
    "spec_file_source",
]

#: Folder of a dataset holding the generated scenes' YAML files.
SCENES_FOLDER = "scenes"
_SAFE = re.compile(r"[^A-Za-z0-9._-]+")
#: Most generated scenes and cameras per scene in one dataset: planning is O(count x views)
#: before the first render, and 10^5 scenes already take days to render on a workstation.
MAX_COUNT = 100_000
#: Version of what the generators draw for a seed, part of the config: a set built by an older
#: version (other light pools, furniture, framing) asks for ``--rebuild`` instead of mixing.
#: 2: saturated lights, ranges obeyed by every material, framed rooms (issue 22).
#: 3: cameras pass the view rule (``scenes.generators.view_rule``, issue 31).
#: 4: ``objects-on-ground``'s library objects take ``--texture-fraction`` too (issue 44).
#: 5: views are also judged on their rendered light (a probe render, issue 47).
GENERATOR_VERSION = 5
MAX_VIEWS = 64


def _daylight_spec(generator: str, share: float, only: bool) -> dict[str, Any]:
    """The source entries of ``--daylight-share`` / ``--daylight-only`` (none at share 0, so
    sets without daylight keep their hash), validated."""
    if not 0.0 <= share <= 1.0 or (share > 0 and generator != "rooms"):
        raise DatasetError(
            f"--daylight-share {share:g}: expected a fraction in 0..1 of the rooms "
            f"generator's scenes (generator {generator!r})"
        )
    if only and share <= 0:
        raise DatasetError(
            "--daylight-only: applies to daylight rooms only; expected --daylight-share F > 0"
        )
    if share <= 0:
        return {}
    # the lamps' balance against the daylight (issue 42): sets of before, whose lamps were
    # not balanced, keep a config hash of their own
    spec: dict[str, Any] = {
        "daylight_share": float(share),
        "daylight_flux_share": [float(v) for v in FLUX_SHARE],
    }
    if only:
        spec["daylight_only"] = True
    return spec


def generator_source(
    generator: str,
    count: int,
    *,
    views: int = 1,
    value_range: Sequence[float] = (2.0, 9.0),
    chroma_range: Sequence[float] = (0.0, 16.0),
    min_coverage: float = 0.15,
    sfu: bool = False,
    gloss: GlossDistribution | None = None,
    light_saturation: Sequence[float] | None = None,
    texture_fraction: float = 0.0,
    daylight_share: float = 0.0,
    daylight_only: bool = False,
) -> str:
    """The canonical ``source`` JSON of a generated set (validated: an impossible range is
    refused here, before any scene is planned); *gloss*, *light_saturation* and a
    *texture_fraction* above 0 enter it only when given, so matte sets and older configs keep
    their source and config hash; so does a *daylight_share* (``rooms`` only) above 0, and
    *daylight_only* (those rooms lit by sun and sky alone) when set."""
    validate_choice(generator, GENERATORS, "scene generator", error=DatasetError)
    try:
        check_ranges(
            (float(value_range[0]), float(value_range[1])),
            (float(chroma_range[0]), float(chroma_range[1])),
        )
    except SceneError as exc:
        raise DatasetError(f"--value-range / --chroma-range: {exc}") from None
    try:
        if light_saturation is not None:
            check_saturation((float(light_saturation[0]), float(light_saturation[1])))
    except SceneError as exc:
        raise DatasetError(f"--light-saturation: {exc}") from None
    if not 0.0 <= texture_fraction <= 1.0:
        raise DatasetError(f"--texture-fraction {texture_fraction:g}: expected a fraction in 0..1")
    if not (1 <= count <= MAX_COUNT and 1 <= views <= MAX_VIEWS):
        raise DatasetError(
            f"--count {count} / --views {views}; expected whole numbers from 1 to "
            f"{MAX_COUNT} scenes and 1 to {MAX_VIEWS} views"
        )
    spec = {
        "generator": generator,
        "count": int(count),
        "views": int(views),
        "value_range": [float(v) for v in value_range],
        "chroma_range": [float(c) for c in chroma_range],
        "min_coverage": float(min_coverage),
        "sfu": bool(sfu),
        "generator_version": GENERATOR_VERSION,
    }
    if gloss is not None and gloss.active:
        glass = (  # absent when off: older configs keep their hash
            {"glass": float(gloss.glass_fraction), "mirrors": float(gloss.mirror_fraction)}
            if gloss.glass_active
            else {}
        )
        spec["gloss"] = {
            "glossy": float(gloss.glossy_fraction),
            "metallic": float(gloss.metal_fraction),
            "roughness_range": [float(v) for v in gloss.roughness_range],
        } | glass
    if light_saturation is not None:  # absent when not given: older configs keep their hash
        spec["light_saturation"] = [float(v) for v in light_saturation]
    if texture_fraction > 0:
        spec["texture_fraction"] = float(texture_fraction)
    spec |= _daylight_spec(generator, daylight_share, daylight_only)
    return json.dumps(spec, sort_keys=True, allow_nan=False)


def files_source(
    paths: Sequence[str | os.PathLike[str]],
    *,
    materials: Mapping[str, str] | None = None,
    default_spectrum: str | None = None,
    resolution: tuple[int, int] | None = None,
    new_sample: bool = False,
    colours_from_asset: bool = True,
    approximate: bool = False,
    semantic: SemanticRules | None = None,
) -> str:
    """The canonical ``source`` JSON of a set of scene files (each must exist): rendered at
    *resolution* ``(W, H)``, else at each file's own camera size; a saved generated scene as
    its own sample unless *new_sample*; *colours_from_asset* (always in the JSON since issue 41
    made it the default; a config without it was written before and means False, so older
    datasets rebuild as they were): the colours and textures the files state;
    *approximate* (in the JSON only when set, so older configs keep their hash): Mitsuba XML
    content without exact ground truth approximated; *semantic* (likewise): the
    ``--semantic-map`` rules, before the default map's."""
    entries = []
    for p in paths:
        if not str(p):  # Path("") is the working folder
            raise DatasetError("--scenes '': an empty path; expected scene files")
        path = Path(p).resolve()
        if path.exists() and not path.is_file():  # a folder: name what the option takes
            raise DatasetError(
                f"--scenes {str(p)!r} is {file_type(path)}; expected scene files (.yaml, .xml, "
                f".blend, .obj/.ply/.glb...), e.g. {os.path.join(str(p), '*.yaml')}"
            )
        if not path.is_file():
            raise DatasetError(f"--scenes {str(p)!r}: no such file")
        scene_file_kind(path)
        entries.append({"path": str(path), "sha256": file_sha256(path)})
    stems = [_SAFE.sub("-", scene_file_name(Path(e["path"]))) for e in entries]
    dupes = sorted({s for s in stems if stems.count(s) > 1})
    if dupes:
        raise DatasetError(f"--scenes: several scenes named {dupes}; scene names must be unique")
    spec: dict[str, Any] = {
        "scenes": entries,
        "materials": dict(sorted((materials or {}).items())),
        "default_spectrum": default_spectrum,
        "new_sample": bool(new_sample),
        "resolution": None if resolution is None else [int(v) for v in resolution],
    }
    spec["colours_from_asset"] = bool(colours_from_asset)
    if approximate:
        if not any(scene_file_kind(e["path"]) in ("mitsuba", "blend") for e in entries):
            raise DatasetError(
                "--approximate applies to Mitsuba XML scenes and .blend worlds; no --scenes file "
                "is either"
            )
        spec["approximate"] = True
    if semantic is not None:  # --semantic-map's rules themselves (in the JSON only when given)
        spec["semantic_map"] = semantic.record()
    ids = [str(file_sample(e["path"], new_sample=new_sample)[0]) for e in entries]
    dupes = sorted({i for i in ids if ids.count(i) > 1})
    if dupes:
        raise DatasetError(
            f"--scenes: several files are sample {dupes}; add --new-sample to "
            "render saved scenes as new samples"
        )
    return json.dumps(spec, sort_keys=True, allow_nan=False)


def saved_sample(path: str | os.PathLike[str]) -> tuple[SampleId, int] | None:
    """The sample a generated build saved this YAML scene for (``metadata.sample``: id and
    seed), or ``None`` for any other scene file. A malformed record is a one-line error."""
    if scene_file_kind(Path(path)) != "yaml":
        return None
    doc = load_yaml_file(Path(path))
    meta = doc.get("metadata") if isinstance(doc, dict) else None
    record = meta.get("sample") if isinstance(meta, dict) else None
    if record is None:
        return None
    seed = record.get("seed") if isinstance(record, dict) else None
    text = str(record.get("id")) if isinstance(record, dict) else ""
    try:  # a folder name: letters, digits, '.', '_', '-' only (the file is untrusted input)
        sid = (
            SampleId.parse(text)
            if _SAFE.sub("-", text) == text and not text.startswith(".")
            else None
        )
    except SpectrinsicError:
        sid = None
    if sid is None or isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**32:
        raise DatasetError(
            f"{path}: metadata.sample {record!r}; expected {{id: <sample id>, "
            "seed: <0..2^32-1>}} as a generated build saves it"
        )
    return sid, seed


def file_sample(path: str | os.PathLike[str], *, new_sample: bool) -> tuple[SampleId, int | None]:
    """A scene file's sample id and seed: the saved sample's (:func:`saved_sample`) unless
    *new_sample*, else ``<name>__v0__file`` (:func:`scene_file_name`) with no seed (the root seed's, when planned)."""
    saved = None if new_sample else saved_sample(path)
    if saved is not None:
        return saved
    return SampleId(_SAFE.sub("-", scene_file_name(Path(path))), 0, "file"), None


def scene_file_name(path: Path) -> str:
    """The scene's own ``name`` for a YAML scene file that has one, else the file's stem."""
    if scene_file_kind(path) == "yaml":
        doc = load_yaml_file(path)
        name = doc.get("name") if isinstance(doc, dict) else None
        if isinstance(name, str) and name.strip() and not name.startswith("."):
            return name.strip()
    return path.stem


def _generator_options(spec: Mapping[str, Any], config: DatasetConfig, data_dir: str | None) -> Any:
    sfu_r: tuple[str, ...] = ()
    sfu_i: tuple[str, ...] = ()
    if spec.get("sfu"):
        try:
            sfu_r = tuple(list_spectra("sfu", data_dir=data_dir))
            sfu_i = tuple(list_spectra("sfu-illum", data_dir=data_dir))
        except Exception as exc:  # noqa: BLE001 - any data-directory failure reads the same
            raise DatasetError(f"--sfu needs the SFU data directory (--data-dir): {exc}") from exc
    try:
        dist = MaterialDistribution(
            tuple(spec["value_range"]),
            tuple(spec["chroma_range"]),
            sfu_fraction=0.5 if sfu_r else 0.0,
            texture_fraction=float(spec.get("texture_fraction", 0.0)),
        )
    except (SceneError, TypeError, ValueError) as exc:
        raise DatasetError(f"source materials: {exc}") from exc
    g = spec.get("gloss") or {}
    try:
        gloss = GlossDistribution(
            float(g.get("glossy", 0.0)),
            float(g.get("metallic", 0.0)),
            tuple(g.get("roughness_range", (0.0, 0.3))),
            glass_fraction=float(g.get("glass", 0.0)),
            mirror_fraction=float(g.get("mirrors", 0.0)),
        )  # type: ignore[arg-type]
    except (SceneError, TypeError, ValueError) as exc:
        raise DatasetError(f"source gloss {g!r}: {exc}") from exc
    saturation = spec.get("light_saturation")
    return GeneratorOptions(
        width=config.width,
        height=config.height,
        views=int(spec["views"]),
        materials=dist,
        min_coverage=float(spec["min_coverage"]),
        sfu_reflectances=sfu_r,
        sfu_illuminants=sfu_i,
        gloss=gloss,
        light_saturation=None if saturation is None else tuple(saturation),
        daylight_share=float(spec.get("daylight_share", 0.0)),
        daylight_only=bool(spec.get("daylight_only", False)),
    )


def plan_source_samples(
    out: str, config: DatasetConfig, *, data_dir: str | None, render_threads: int | None
) -> list[SampleTask]:
    """The :class:`~spectrinsic.pipeline.tasks.SampleTask` list of ``config.source``."""
    spec = json.loads(config.source or "{}")
    rows: list[tuple[str, int, str, Any]] = []
    if "generator" in spec:
        gen, options = spec["generator"], _generator_options(spec, config, data_dir)
        for i in range(int(spec["count"])):
            name, family = generated_scene_name(gen, i), generated_family(config.seed, gen, i)
            rows += [
                (name, v, family, GeneratedSource(gen, config.seed, i, v, options))
                for v in range(options.views)
            ]
    else:
        return _file_tasks(spec, out, config, data_dir=data_dir, render_threads=render_threads)
    return [
        SampleTask.planned(
            SampleId(name, v, cond),
            config,
            out,
            data_dir=data_dir,
            render_threads=render_threads,
            source=src,
        )
        for name, v, cond, src in rows
    ]


def semantic_rules(spec: Mapping[str, Any]) -> SemanticRules:
    """The ``--semantic-map`` rules a files source records (none: the default map alone)."""
    record = spec.get("semantic_map")
    return SemanticRules() if record is None else rules_from_record(record, "--semantic-map")


def spec_file_source(spec: Mapping[str, Any], path: str) -> FileSource:
    """The :class:`FileSource` of scene file *path* under a files source's *spec*: its
    ``resolution`` (else the file's camera), material map, default spectrum and reading flags."""
    width, height = spec.get("resolution") or (None, None)
    return FileSource(
        path,
        width,
        height,
        tuple(sorted((spec.get("materials") or {}).items())),
        spec.get("default_spectrum"),
        colours_from_asset=bool(spec.get("colours_from_asset", False)),
        approximate=bool(spec.get("approximate")),
        semantic=semantic_rules(spec),
    )


def _file_tasks(
    spec: Mapping[str, Any],
    out: str,
    config: DatasetConfig,
    *,
    data_dir: str | None,
    render_threads: int | None,
) -> list[SampleTask]:
    """One task per scene file: the file's camera size unless the spec's ``resolution``; a
    saved generated scene keeps its sample id and seed unless ``new_sample``."""
    tasks = []
    for entry in spec["scenes"]:
        src = spec_file_source(spec, entry["path"])
        sid, seed = file_sample(entry["path"], new_sample=bool(spec.get("new_sample")))
        task = SampleTask.planned(
            sid, config, out, data_dir=data_dir, render_threads=render_threads, source=src
        )
        tasks.append(task if seed is None else dataclasses.replace(task, seed=seed))
    return tasks


def save_generated(
    out_dir: str | os.PathLike[str], sample_id: str, scene: Scene, seed: int
) -> Path:
    """Write a generated scene as ``<out>/scenes/<sample id>.yaml`` (meshes beside it), its
    ``metadata.sample`` naming the sample (id and render *seed*) so re-rendering the file
    reproduces it (:func:`saved_sample`)."""
    folder = Path(out_dir) / SCENES_FOLDER
    folder.mkdir(parents=True, exist_ok=True)
    record = {**scene.metadata, "sample": {"id": sample_id, "seed": int(seed)}}
    return save_scene(dataclasses.replace(scene, metadata=record), folder / f"{sample_id}.yaml")


def check_scene_integrator(config: DatasetConfig, scene: Scene, path: str) -> None:
    """Refuse, before the first sample, a scene file (``--scenes``, ``render --ground-truth``)
    with glossy materials or a spectral texture whose diagonal modes would render with the
    passes integrator: its sample would fail (the passes render neither)."""
    if not diagonal_mode_names(config.render.modes):
        return
    if resolve_integrator(config.render.integrator, config.render.variant) != "passes":
        return
    glossy = any(m.glossy for m in scene.materials)
    if glossy or scene.textured:
        what = "glossy, metal or glass materials" if glossy else "a spectral texture"
        raise DatasetError(
            f"{path}: holds {what}, which the passes integrator cannot render in the diagonal "
            "modes; use --integrator single on a JIT (LLVM/CUDA) variant"
        )


def check_integrator_plan(config: DatasetConfig) -> None:
    """Refuse, before the first sample, a generated set with glossy or metal materials
    (``--glossy``/``--metallic``) whose diagonal modes would render with the passes integrator
    (``--integrator passes``, or ``single`` on a scalar variant): every sample would fail."""
    spec = json.loads(config.source or "{}")
    if "generator" not in spec or "gloss" not in spec:
        return
    if not diagonal_mode_names(config.render.modes):
        return
    if resolve_integrator(config.render.integrator, config.render.variant) == "passes":
        raise DatasetError(
            "--glossy/--metallic with the passes integrator: the diagonal modes render glossy "
            "and metal materials only with --integrator single on a JIT (LLVM/CUDA) variant"
        )
