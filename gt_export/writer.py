"""Writing samples and datasets: EXR data, PNG previews, ``meta.json``, manifest and card.

A sample folder ``<out_dir>/<sample_id>/`` holds

* ``image.exr``, ``intrinsics.exr``, ``geometry.exr``, ``camera-<slug>.exr`` (and ``cube.exr``
  on request): float32 layers with named channels (see ``meta.json["layers"]``);
* ``previews/<layer>.png``: 8-bit sRGB previews for looking only;
* ``scene.json``: the scene as plain data (compact JSON); ``meta.json``: provenance, materials, lights,
  matrices, the units of every layer. ``meta.json`` is written last.

Everything is written into a hidden temporary folder next to the target and renamed into
place, so a folder named ``<sample_id>`` is always whole: partial output never looks complete.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import shutil
import tempfile
import uuid
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, fields, is_dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import png
from spectrinsic.gt_export.exr import write_exr
from spectrinsic.gt_export.integrity import (
    HASHES_KEY,
    MANIFEST_NAME,
    META_NAME,
    TMP_PREFIX,
    file_hashes,
    file_sha256,
    guarded_write,
    remove_owned_temporaries,
    replaceable_sample,
    sample_problem,
)
from spectrinsic.gt_export.layers import GroundTruth, Layer, compute_ground_truth, identities
from spectrinsic.gt_export.transport_file import TRANSPORT_NAME, write_transport
from spectrinsic.provenance import software_versions
from spectrinsic.scenes.model import LIGHT_FIELDS, LIGHT_PLACEMENT, Scene, scene_hash

if TYPE_CHECKING:
    from spectrinsic.render.transport import LightTransport

__all__ = [
    "FORMAT_VERSION",
    "META_NAME",
    "SCENE_NAME",
    "MANIFEST_NAME",
    "CARD_NAME",
    "DEFAULT_CAMERAS",
    "config_hash",
    "export_sample",
    "is_complete",
    "sample_dirs",
    "remove_stale_temporaries",
    "write_manifest",
    "write_dataset_card",
    "file_sha256",
    "read_template",
]

log = logging.getLogger(__name__)

#: 2: shading from spectral irradiance, residual, noise, denoised layers (1: per-channel ratio).
FORMAT_VERSION = 2
#: The rendered scene as plain data (:func:`spectrinsic.scenes.model.scene_to_dict`), compact JSON.
SCENE_NAME = "scene.json"
CARD_NAME = "DATASET.md"
PREVIEW_DIR = "previews"
#: Cameras exported by default when the 31-band cube is available (shipped by colour-science).
DEFAULT_CAMERAS: tuple[str, ...] = ("camera:Nikon 5100 (NPL)", "camera:Sigma SDMerill (NPL)")
#: Significant digits of every float in ``meta.json`` (fitted matrices, light colours, noise
#: figures): far above their physical accuracy, and far enough below float64's 15.9 that the
#: last-bit differences of floating-point reductions between machines never reach the file.
META_DIGITS = 12
#: Render metadata that varies from run to run and so is not written (files stay reproducible).
_VOLATILE_META = ("timings",)
#: Distributions whose versions are recorded.


# ----------------------------------------------------------------------------------------------
# Plain data and hashes


def _jsonable(value: Any, digits: int | None = None) -> Any:
    """Plain JSON data of *value*; floats rounded to *digits* significant digits if given."""
    if is_dataclass(value) and not isinstance(value, type):
        return {f.name: _jsonable(getattr(value, f.name), digits) for f in fields(value)}
    if isinstance(value, Mapping):
        return {str(k): _jsonable(v, digits) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        finite = value.dtype.kind in "biu" or (value.dtype.kind == "f" and np.isfinite(value).all())
        if finite and (digits is None or value.dtype.kind != "f"):
            return value.tolist()  # plain bools, ints and finite floats all the way down
        return _jsonable(value.tolist(), digits)
    if isinstance(value, np.generic):
        return _jsonable(value.item(), digits)
    if isinstance(value, (list, tuple)):
        return [_jsonable(v, digits) for v in value]
    if isinstance(value, float):
        if not np.isfinite(value):
            return str(value)
        return value if digits is None else float(f"{value:.{digits}g}")
    if value is None or isinstance(value, (str, int, bool)):
        return value
    return str(value)


def _dump_json(path: Path, data: Any, *, compact: bool = False, digits: int | None = None) -> None:
    """Write *data* as sorted-key JSON: indented, or *compact* (one line, no spaces) for large
    files, which the json module's C encoder then writes (it is bypassed whenever indenting).
    *digits* rounds every float to that many significant digits."""
    layout: dict[str, Any] = {"separators": (",", ":")} if compact else {"indent": 2}
    text = json.dumps(_jsonable(data, digits), sort_keys=True, ensure_ascii=False, **layout) + "\n"
    with guarded_write(path):
        path.write_text(text, encoding="utf-8")


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
    blob = json.dumps(_jsonable(config), sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    return hashlib.sha256(blob.encode("utf-8")).hexdigest()


# ----------------------------------------------------------------------------------------------
# Previews


#: A preview and how its pixels encode the layer: ``{"kind": "srgb", "scale": k}`` (PNG =
#: sRGB-encoded ``clip(value × k)``, so ``value = decode(PNG) / k`` below the clip),
#: ``{"kind": "colormap", "cmap", "vmin", "vmax"}`` (false colour of a scalar) or
#: ``{"kind": "categorical"}`` (ids, normals, mask).
Preview = tuple[np.ndarray, dict[str, Any]]

#: Layers that share one exposure per sample, so brightness differences between them are real:
#: every image mode and camera image uses ``image``'s, every shading ``shading``'s.
_EXPOSURE_OF = (("image", "image"), ("shading", "shading"))


def _srgb(data: np.ndarray, scale: float) -> Preview:
    return png.encode_srgb8(data, scale), {"kind": "srgb", "scale": float(scale)}


def _colour_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    base = next((b for prefix, b in _EXPOSURE_OF if layer.name.startswith(prefix)), layer.name)
    return _srgb(layer.data, png.exposure(layers.get(base, layer).data))


def _reflectance_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _srgb(layer.data, 1.0)  # absolute scale: the perfect white is 1


def _illuminant_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    # unit luminance: D65 light is (1, 1, 1); a scale of 1/2 keeps saturated light unclipped
    return _srgb(layer.data, 0.5)


def _grey_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _srgb(np.repeat(layer.data[..., None], 3, axis=-1), png.exposure(layer.data))


def _colormap(values: np.ndarray, vmin: float, vmax: float, cmap: str = "magma",
              mask: np.ndarray | None = None) -> Preview:
    return (png.false_colour(values, mask=mask, cmap=cmap, vmin=vmin, vmax=vmax),
            {"kind": "colormap", "cmap": cmap, "vmin": float(vmin), "vmax": float(vmax)})


def _error_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _colormap(layer.data, 0.0, 0.1)


def _residual_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    """Magnitude of the residual relative to the image: 0 (black) to 10 % (bright)."""
    base = layers.get(layer.name.replace("residual", "image", 1).replace("image_raw", "image"))
    norm = np.linalg.norm(base.data, axis=-1) if base is not None else np.ones(layer.data.shape[:2])
    rel = np.divide(np.linalg.norm(layer.data, axis=-1), norm, out=np.zeros(norm.shape), where=norm > 0)
    preview, encoding = _colormap(rel, 0.0, 0.1)
    return preview, {**encoding, "of": "‖residual‖ / ‖image‖"}


def _noise_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _colormap(layer.data, 0.0, 0.2)


def _mask_of(layers: Mapping[str, Layer]) -> np.ndarray | None:
    return layers["mask"].data > 0.5 if "mask" in layers else None


def _depth_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    mask = _mask_of(layers)
    valid = layer.data[mask] if mask is not None else layer.data.ravel()
    lo, hi = (float(np.percentile(valid, 1)), float(np.percentile(valid, 99))) if valid.size else (0.0, 1.0)
    return _colormap(layer.data, lo, hi, cmap="viridis", mask=mask)


def _categorical(rgb8: np.ndarray) -> Preview:
    return rgb8, {"kind": "categorical"}


def _normals_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _categorical(png.normals_preview(layer.data, _mask_of(layers)))


def _ids_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _categorical(png.id_colours(layer.data))


def _mask_preview(layer: Layer, layers: Mapping[str, Layer]) -> Preview:
    return _categorical(np.repeat((layer.data > 0.5).astype(np.uint8)[..., None] * 255, 3, axis=-1))


#: (layer-name prefix, preview maker); the first matching prefix wins; no match, no preview.
_PREVIEWS: tuple[tuple[str, Callable[[Layer, Mapping[str, Layer]], Preview]], ...] = (
    ("image", _colour_preview),
    ("shading_grey", _grey_preview),
    ("shading", _colour_preview),
    ("reflectance", _reflectance_preview),
    ("illuminant", _illuminant_preview),
    ("error_", _error_preview),
    ("residual", _residual_preview),
    ("noise_", _noise_preview),
    ("depth", _depth_preview),
    ("normals", _normals_preview),
    ("material_id", _ids_preview),
    ("object_id", _ids_preview),
    ("mask", _mask_preview),
)


def _preview_name(layer: Layer) -> str:
    base, _, camera = layer.name.partition("/")
    return f"{base}--{layer.group.removeprefix('camera-')}.png" if camera else f"{base}.png"


# ----------------------------------------------------------------------------------------------
# One sample


def _layer_records(gt: GroundTruth, previews: Mapping[str, tuple[str, dict[str, Any]]]) -> dict[str, Any]:
    return {
        layer.name: {
            "file": f"{layer.group}.exr",
            "exr_layer": layer.name.split("/", 1)[0],
            "channels": list(layer.channels),
            "shape": list(layer.data.shape),
            "dtype": "float32",
            "units": layer.units,
            "nonnegative": layer.nonnegative,
            "preview": previews[layer.name][0] if layer.name in previews else None,
            "preview_encoding": previews[layer.name][1] if layer.name in previews else None,
        }
        for layer in gt.layers.values()
    }


def _meta(
    scene: Scene, result: Any, gt: GroundTruth, *, sample_id: str, config: Mapping[str, Any],
    seed: int, previews: Mapping[str, tuple[str, dict[str, Any]]], files: Sequence[str],
) -> dict[str, Any]:
    from spectrinsic.spectra import DEFAULT_WAVELENGTHS, get_spectrum

    render_meta = {k: v for k, v in (getattr(result, "meta", None) or {}).items()
                   if k not in _VOLATILE_META}
    lights = []
    for record in gt.lights:
        unused = set(LIGHT_PLACEMENT) - set(LIGHT_FIELDS[record.kind])
        entry = {k: v for k, v in asdict(record).items() if k not in unused}
        entry["spd"] = get_spectrum(record.spectrum).on(DEFAULT_WAVELENGTHS)
        lights.append(entry)
    height, width = gt.layers["image"].data.shape[:2]
    return {
        "format_version": FORMAT_VERSION,
        "sample_id": sample_id,
        "scene": scene.name,
        "scene_hash": scene_hash(scene),
        "scene_metadata": scene.metadata,
        "config_hash": config_hash(config),
        "seed": int(seed),
        "variants": sorted(set((render_meta.get("variants") or {}).values())),
        "render": render_meta,
        "reference_mode": gt.reference_mode,
        "size": [height, width],
        "spectral_grid": {
            "ground_truth": "360-830 nm at 1 nm (CIE 1931 grid); colours integrated by the rectangle rule",
            "render": render_meta.get("wavelengths"),
            "lights_spd": {"start_nm": 380.0, "end_nm": 780.0, "step_nm": 5.0},
        },
        "materials": gt.materials,
        "objects": {str(m.object_id): m.name for m in scene.meshes},
        "lights": lights,
        "cameras": [c.split(":", 1)[-1] for c in gt.cameras],
        "cube_sensors": gt.cube_sensors,
        "matrices": gt.matrices,
        "layers": _layer_records(gt, previews),
        "identities": identities(gt),
        "denoised_layers": list(gt.denoised),
        "noise": gt.noise,
        "shading_clipping": gt.clipping,
        "files": sorted(files),
        "versions": software_versions(),
    }


def _fill_folder(folder: Path, scene: Scene, result: Any, gt: GroundTruth, *,
                 transport: LightTransport | None = None,
                 **meta_kw: Any) -> None:
    files: list[str] = []
    groups: dict[str, list[Layer]] = {}
    for layer in gt.layers.values():
        groups.setdefault(layer.group, []).append(layer)
    for group, members in groups.items():
        name = f"{group}.exr"
        write_exr(
            folder / name,
            {layer.name.split("/", 1)[0]: layer.data for layer in members},
            channel_names={layer.name.split("/", 1)[0]: layer.channels for layer in members},
            attributes={"spectrinsic.sample": meta_kw["sample_id"]},
        )
        files.append(name)
    (folder / PREVIEW_DIR).mkdir()
    previews: dict[str, tuple[str, dict[str, Any]]] = {}
    for layer in gt.layers.values():
        maker = next((f for prefix, f in _PREVIEWS if layer.name.startswith(prefix)), None)
        if maker is None:
            continue
        rel = f"{PREVIEW_DIR}/{_preview_name(layer)}"
        rgb8, encoding = maker(layer, gt.layers)
        png.write_png(folder / rel, rgb8)
        previews[layer.name] = (rel, encoding)
        files.append(rel)
    # the Scene itself, not scene_to_dict(scene): _jsonable makes the same plain data of it, but
    # converts its vertex and face arrays whole rather than element by element
    _dump_json(folder / SCENE_NAME, scene, compact=True)
    files.append(SCENE_NAME)
    # meta.json last: its presence (with the right config hash) marks the folder complete; it
    # records the SHA-256 of every other file, so a resumed build can tell an intact sample
    record = None
    if transport is not None:  # the per-light transport, for exact relighting
        record = write_transport(folder, transport, result.aovs["coverage"], sample_id=meta_kw["sample_id"])
        record["cameras"] = list(gt.cameras)  # full sensor-set names, to relight the camera layers
        files.append(TRANSPORT_NAME)
    meta = _meta(scene, result, gt, previews=previews, files=files, **meta_kw)
    if record is not None:
        meta["transport"] = record
    meta[HASHES_KEY] = file_hashes(folder, files)
    _dump_json(folder / META_NAME, meta, digits=META_DIGITS)


def export_sample(
    out_dir: str | os.PathLike[str],
    scene: Scene,
    result: Any,
    *,
    sample_id: str,
    config: Mapping[str, Any],
    seed: int,
    cameras: Sequence[str] | None = None,
    write_cube: bool = False,
    denoise: bool = False,
    data_dir: str | os.PathLike[str] | None = None,
    transport: LightTransport | None = None,
) -> Path:
    """Compute every ground-truth layer of a rendered sample and write it atomically.

    Parameters
    ----------
    out_dir
        Dataset folder; the sample goes to ``out_dir/sample_id``.
    scene
        The rendered scene.
    result
        A :class:`~spectrinsic.render.result.RenderResult`, or any record with its fields
        (``images``, ``raw``, ``per_light``, ``direct``, ``aovs``, ``meta``, ``batch_raw``);
        never a live renderer.
    sample_id
        Folder name, e.g. ``"obj-vase__v0__two-colour-a"``.
    config
        The settings the sample was built with; ``meta.json`` records :func:`config_hash` of it.
    seed
        The sample's render seed.
    cameras
        Camera sensor sets for per-camera layers; default :data:`DEFAULT_CAMERAS` when the
        render has the 31-band cube, none otherwise.
    write_cube
        Also write the multispectral cube (``cube.exr``).
    denoise
        Compute shading, residual and illuminant from the OIDN-denoised irradiance.
    data_dir
        Spectral data directory (for ``sfu:``/data-directory cameras).
    transport
        A :class:`~spectrinsic.render.transport.LightTransport` of this render to store as
        ``transport.exr`` (:mod:`~spectrinsic.gt_export.transport_file`), for exact
        relighting (:func:`spectrinsic.gt_export.relight.relight`).

    Returns
    -------
    Path
        The complete sample folder.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    if not sample_id or "/" in sample_id or sample_id.startswith("."):
        raise DatasetError(f"sample id {sample_id!r}: expected a plain folder name")
    if cameras is None:
        cameras = DEFAULT_CAMERAS if "bands31" in (getattr(result, "raw", None) or {}) else ()
    gt = compute_ground_truth(scene, result, cameras=cameras, write_cube=write_cube,
                              denoise=denoise, data_dir=data_dir)
    final = out_dir / sample_id
    tmp = Path(tempfile.mkdtemp(prefix=f"{TMP_PREFIX}{sample_id}-", dir=out_dir))
    try:
        tmp.chmod(0o755)
        _fill_folder(tmp, scene, result, gt, sample_id=sample_id, config=config, seed=seed,
                     transport=transport)
        _move_into_place(tmp, final, config_hash(config))
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    log.debug("wrote sample %s", final)
    return final


def _move_into_place(tmp: Path, final: Path, chash: str) -> None:
    if final.exists() or final.is_symlink():
        # an older version: move it aside first, so no moment shows a mixed folder; a folder
        # spectrinsic did not write (or one holding a user's file) is never replaced
        replaceable_sample(final)
        aside = final.with_name(f"{TMP_PREFIX}old-{final.name}-{uuid.uuid4().hex[:8]}")
        final.rename(aside)
        shutil.rmtree(aside, ignore_errors=True)
    try:
        tmp.rename(final)
    except OSError:
        # another worker finished the same sample meanwhile (e.g. a retried distributed task)
        if is_complete(final, chash):
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            raise


def is_complete(sample_dir: str | os.PathLike[str], config_hash: str) -> bool:
    """True iff *sample_dir* holds a ``meta.json`` with this *config_hash* and all its files,
    each matching its recorded SHA-256 (see :func:`~spectrinsic.gt_export.integrity.sample_problem`)."""
    return sample_problem(sample_dir, config_hash) is None


def sample_dirs(dataset_dir: str | os.PathLike[str]) -> list[Path]:
    """Sample folders of a dataset (visible sub-folders holding ``meta.json``), sorted by name."""
    root = Path(dataset_dir)
    if not root.is_dir():
        raise DatasetError(f"dataset folder {str(root)!r} does not exist")
    return sorted(p for p in root.iterdir()
                  if p.is_dir() and not p.name.startswith(".") and (p / META_NAME).is_file())


def remove_stale_temporaries(dataset_dir: str | os.PathLike[str]) -> list[Path]:
    """Delete spectrinsic's temporaries left by interrupted writes; return what was removed.

    Only names starting with :data:`TMP_PREFIX`, and only in a recognised dataset folder. Call
    it only when no other writer works on *dataset_dir*.
    """
    return remove_owned_temporaries(Path(dataset_dir))


# ----------------------------------------------------------------------------------------------
# Dataset level


def _read_meta(sample: Path) -> dict[str, Any]:
    try:
        return json.loads((sample / META_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise DatasetError(f"{sample / META_NAME}: cannot be read as JSON ({exc})") from exc


def _sample_files(sample: Path) -> Iterable[Path]:
    return sorted(p for p in sample.rglob("*") if p.is_file())


def _spectral_provenance(metas: Sequence[Mapping[str, Any]], data_dir: Any) -> dict[str, Any]:
    from spectrinsic.config import resolve_data_dir

    used: set[str] = set()
    for meta in metas:
        used.update(meta.get("materials", {}).values())
        used.update(light["spectrum"] for light in meta.get("lights", []))
        used.update(f"camera:{c}" for c in meta.get("cameras", []))
        if meta.get("cube_sensors"):
            used.add(meta["cube_sensors"])
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
    metas = [_read_meta(s) for s in samples]
    manifest = {
        "format_version": FORMAT_VERSION,
        "config": config,
        "config_hash": config_hash(config),
        "seed": config.get("seed"),
        "versions": software_versions(),
        "mitsuba_variants": _variants(metas),
        "spectral_data": _spectral_provenance(metas, data_dir),
        "n_samples": len(samples),
        "noise": noise_summary(metas),
        "split_by": "scene",
        "split_fractions": dict(SPLIT_FRACTIONS),
        "splits": splits_by_scene({s.name: str(m.get("scene")) for s, m in zip(samples, metas)}),
        "samples": {
            s.name: {
                "config_hash": m.get("config_hash"),
                "scene": m.get("scene"),
                "seed": m.get("seed"),
                "files": {p.relative_to(root).as_posix(): file_sha256(p) for p in _sample_files(s)},
            }
            for s, m in zip(samples, metas)
        },
    }
    path = root / MANIFEST_NAME
    tmp = path.with_name(f"{TMP_PREFIX}{MANIFEST_NAME}")
    _dump_json(tmp, manifest)
    tmp.replace(path)
    return path


def _variants(metas: Sequence[Mapping[str, Any]]) -> list[str]:
    """Every Mitsuba variant the samples were rendered with, sorted."""
    return sorted({str(v) for m in metas for v in m.get("variants", [])})


#: Train / val / test shares of the scenes (each scene's samples go to one split).
SPLIT_FRACTIONS: tuple[tuple[str, float], ...] = (("train", 0.8), ("val", 0.1), ("test", 0.1))


def split_of(scene: str) -> str:
    """The split of scene *scene*: its ``seed_from_key(0, "split:" + scene)`` as a fraction of
    2³² against the cumulative :data:`SPLIT_FRACTIONS`. It depends on the scene name only, so a
    scene keeps its split when the set grows and all its views and conditions share it.

    >>> split_of("room-living") == split_of("room-living")
    True
    """
    from spectrinsic.rng import seed_from_key

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


def _diversity_section(root: Path, samples: Sequence[Path], metas: Sequence[Mapping[str, Any]]) -> str:
    """The card's diversity section: splits by scene and ``diversity.png`` (written here)."""
    from spectrinsic.gt_export.diversity import DIVERSITY_NAME, write_diversity

    figure = root / DIVERSITY_NAME
    newest = max((s / META_NAME).stat().st_mtime_ns for s in samples)
    if not figure.is_file() or figure.stat().st_mtime_ns < newest:  # a resumed build: keep it
        write_diversity(root, samples, metas)
    splits = splits_by_scene({s.name: str(m.get("scene")) for s, m in zip(samples, metas, strict=True)})
    counts = ", ".join(f"{k} {len(v)}" for k, v in splits.items())
    return (f"\n## Splits and diversity\n\nSplits by scene (no scene in two splits; "
            f"`manifest.json[\"splits\"]`): {counts} samples.\n\n"
            f"![r, light CCT and xy, materials per image, object coverage, luminance range]"
            f"({DIVERSITY_NAME})\n")


def noise_summary(metas: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """Median over samples of each sample's median and p95 relative standard error, per layer
    and scene kind (``object``/``complex``), and the worst sample's median."""
    out: dict[str, Any] = {}
    for meta in metas:
        kind = (meta.get("scene_metadata") or {}).get("kind", "all")
        for layer, fig in (meta.get("noise") or {}).items():
            if isinstance(fig, Mapping):
                row = (fig["median"], fig["p95"], fig.get("rms", fig["median"]), meta["sample_id"])
                out.setdefault(layer, {}).setdefault(kind, []).append(row)
    summary: dict[str, Any] = {}
    for layer, kinds in out.items():
        for kind, rows in kinds.items():
            worst = max(rows)
            summary.setdefault(layer, {})[kind] = {
                "samples": len(rows), "median_of_medians": float(np.median([r[0] for r in rows])),
                "median_of_p95": float(np.median([r[1] for r in rows])),
                "median_of_rms": float(np.median([r[2] for r in rows])),
                "worst_median": float(worst[0]), "worst_sample": worst[3],
            }
    return summary


def _noise_table(summary: Mapping[str, Any]) -> str:
    if not summary:
        return "Rendered as a single batch: no noise estimate (build with `batches` ≥ 2)."
    lines = ["Relative standard error of the raw Monte Carlo layers, per pixel, from the spread of "
             "independent batches (the denoised layers are measured against converged renders "
             "in `make bench`). Per sample: median, 95th percentile and RMS over its pixels; with two "
             "batches a pixel's estimate has one degree of freedom, so the RMS is the unbiased "
             "figure and the median reads about 0.67 of it.", "",
             "| layer | scenes | samples | median of medians | median of p95 | median of RMS | worst median (sample) |",
             "|---|---|---|---|---|---|---|"]
    for layer, kinds in sorted(summary.items()):
        for kind, row in sorted(kinds.items()):
            lines.append(f"| `{layer}` | {kind} | {row['samples']} | {100 * row['median_of_medians']:.1f} % "
                         f"| {100 * row['median_of_p95']:.1f} % | {100 * row['median_of_rms']:.1f} % "
                         f"| {100 * row['worst_median']:.1f} % "
                         f"(`{row['worst_sample']}`) |")
    return "\n".join(lines)


def read_template(name: str) -> str:
    """Text of a package template (``gt_export/templates/<name>``)."""
    from importlib import resources

    return resources.files("spectrinsic.gt_export").joinpath("templates", name).read_text("utf-8")


def write_dataset_card(
    dataset_dir: str | os.PathLike[str], config: Mapping[str, Any] | None = None
) -> Path:
    """Write ``DATASET.md``: what each layer is, its units, colour space, and how to load it."""
    import string

    root = Path(dataset_dir)
    samples = sample_dirs(root)
    if not samples:
        raise DatasetError(f"dataset folder {str(root)!r} has no complete samples to describe")
    metas = [_read_meta(s) for s in samples]
    rows: dict[str, Any] = {}
    for meta in metas:
        for name, rec in meta["layers"].items():
            rows.setdefault(name, rec)
    table = "\n".join(
        f"| `{name}` | `{rec['file']}` | {', '.join(rec['channels'])} | {rec['units']} |"
        for name, rec in rows.items()
    )
    scenes = sorted({m["scene"] for m in metas})
    text = string.Template(read_template("DATASET.md")).substitute(
        noise_table=_noise_table(noise_summary(metas)),
        n_samples=len(samples),
        n_scenes=len(scenes),
        scenes=", ".join(scenes),
        layer_table=table,
        config_hash=config_hash(config) if config is not None else metas[0].get("config_hash"),
        config=json.dumps(_jsonable(config or {}), indent=2, sort_keys=True),
        versions=json.dumps(software_versions(), indent=2, sort_keys=True),
        variants=", ".join(_variants(metas)),
    ) + _diversity_section(root, samples, metas)
    path = root / CARD_NAME
    with guarded_write(path):
        path.write_text(text, encoding="utf-8")
    return path
