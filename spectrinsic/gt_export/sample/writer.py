"""Writing one sample folder: EXR data, PNG previews, ``scene.json`` and a sealed ``meta.json``.

A sample folder ``<out_dir>/<sample_id>/`` holds

* ``image.exr``, ``intrinsics.exr``, ``geometry.exr``, ``camera-<slug>.exr`` (and ``cube.exr``
  on request): float32 layers with named channels, integer ids as UINT channels (see
  ``meta.json["layers"]``);
* ``previews/<layer>.png``: 8-bit sRGB previews for looking only
  (:mod:`~spectrinsic.gt_export.sample.previews`);
* ``scene.json``: the scene as plain data (compact JSON); ``meta.json``: provenance, materials,
  lights, matrices, the units of every layer, the SHA-256 of every other file and its own seal
  (:func:`~spectrinsic.gt_export.sample.meta_seal`). ``meta.json`` is written last.

Everything is written into a hidden temporary folder next to the target and renamed into
place, so a folder named ``<sample_id>`` is always whole: partial output never looks complete.
The file names and the JSON layout come from :mod:`~spectrinsic.gt_export.sample`; readers
take them from there too, never from this module.
"""

from __future__ import annotations

import functools
import logging
import os
import re
import shutil
import tempfile
import uuid
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ...errors import DatasetError, WriteError
from ...file_writes import write_text_file
from ...provenance import software_versions
from ...render.result import RenderResult
from ...scenes.envmaps import portable_map_files
from ...scenes.model import (
    GLASS_TINTS,
    LIGHT_FIELDS,
    LIGHT_PLACEMENT,
    Scene,
    scene_record_hash,
    scene_to_dict,
)
from ...scenes.semantic import class_table
from ...spectra import DEFAULT_WAVELENGTHS, get_spectrum
from ...spectra.user_spectra import portable_names, spectrum_files
from ..formats import png
from ..formats.exr import write_exr
from ..layers import (
    GroundTruth,
    LayerSettings,
    compute_ground_truth,
    identities,
)
from ..layers.records import camera_key
from . import (
    FORMAT_VERSION,
    HASHES_KEY,
    META_DIGITS,
    META_NAME,
    PREVIEW_DIR,
    SCENE_NAME,
    SEAL_KEY,
    TMP_PREFIX,
    canonical_json,
    config_hash,
    file_sha256,
    meta_seal,
    plain_data,
)
from .integrity import replaceable_sample, sample_problem
from .previews import preview_maker, preview_path, shown_layers
from .sensor import SensorOutput, sensor_output, write_sensor_files
from .stored_layers import compression_of, stored_layers
from .transport_cube import CubeFactors, cube_factors, with_cube
from .transport_exr import TRANSPORT_NAME, write_transport
from .write_pool import FileWrites

if TYPE_CHECKING:
    from ...render.algebra.light_transport import LightTransport

__all__ = [
    "export_sample",
    "is_complete",
    "remove_sample_temporaries",
]

log = logging.getLogger(__name__)

#: Render metadata that varies from run to run and so is not written (files stay reproducible).
_VOLATILE_META = ("timings",)


def _dump_json(path: Path, data: Any, *, compact: bool = False) -> None:
    write_text_file(path, canonical_json(data, compact=compact))


def _layer_records(
    gt: GroundTruth, previews: Mapping[str, tuple[str, dict[str, Any]]]
) -> dict[str, Any]:
    return {
        layer.name: {
            "file": f"{layer.group}.exr",
            "exr_layer": layer.name.split("/", 1)[0],
            "channels": list(layer.channels),
            "shape": list(layer.data.shape),
            "dtype": str(layer.data.dtype),
            "units": layer.units,
            "nonnegative": layer.nonnegative,
            "preview": previews[layer.name][0] if layer.name in previews else None,
            "preview_encoding": previews[layer.name][1] if layer.name in previews else None,
        }
        for layer in gt.layers.values()
    }


def _meta(
    scene: Scene,
    result: RenderResult,
    gt: GroundTruth,
    *,
    sample_id: str,
    config: Mapping[str, Any],
    seed: int,
    previews: Mapping[str, tuple[str, dict[str, Any]]],
    files: Sequence[str],
    scene_record: Mapping[str, Any],
    scene_folder: Path | None,
) -> dict[str, Any]:
    render_meta = {k: v for k, v in result.meta.items() if k not in _VOLATILE_META}
    lights = []
    for record in gt.lights:
        unused = set(LIGHT_PLACEMENT) - set(LIGHT_FIELDS[record.kind])
        entry = {k: v for k, v in asdict(record).items() if k not in unused}
        entry["spd"] = get_spectrum(record.spectrum).on(DEFAULT_WAVELENGTHS)
        lights.append(entry)
    height, width = gt.layers["image"].data.shape[:2]
    files_used = spectrum_files(
        [m.spectrum for m in scene.materials]
        + [getattr(m, k) for m in scene.materials for k in GLASS_TINTS if getattr(m, k)]
        + [li.spectrum for li in scene.lights]
        + [*gt.cameras],
        scene_folder,
    ) + list(scene.metadata.get("spectrum_files", []))  # the .spd files a Mitsuba XML read
    extra: dict[str, Any] = {"spectrum_files": files_used} if files_used else {}
    if "semantic" in gt.layers:  # the class table of the semantic layer's ids
        extra["semantic_classes"] = class_table()
    return {
        "format_version": FORMAT_VERSION,
        "sample_id": sample_id,
        "scene": scene.name,
        "scene_hash": scene_record_hash(scene_record),
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
        "cameras": [camera_key(c).split(":", 1)[-1] for c in gt.cameras],
        "cube_sensors": gt.cube_sensors,
        "matrices": gt.matrices,
        "layers": _layer_records(gt, previews),
        "identities": identities(gt),
        "denoised_layers": list(gt.denoised),
        "noise": gt.noise,
        "shading_clipping": gt.clipping,
        "working_space": gt.working_space.record(),
        "residual_share": gt.residual_share,
        "files": sorted(files),
        "versions": software_versions(),
    } | extra


def _write_layers(
    writes: FileWrites, gt: GroundTruth, sample_id: str, coverage: Any, cube: CubeFactors | None
) -> tuple[list[str], dict[str, Any]]:
    """One EXR file per layer group, layers that their stored factors rebuild bit for bit
    stored as those (:mod:`~spectrinsic.gt_export.sample.layer_storage`), handed to *writes*;
    return the file names and ``meta.json["storage"]``."""
    stored = stored_layers(gt, coverage, identities(gt), cube)
    for name, arrays in stored.arrays.items():
        writes.submit(
            name,
            functools.partial(
                write_exr,
                layers=arrays,
                channel_names=stored.channels[name],
                attributes={"spectrinsic.sample": sample_id} | stored.attributes.get(name, {}),
                half=[k for k in stored.half if k in arrays],
                compression=compression_of(name),
            ),
        )
    return list(stored.arrays), stored.record()


def _write_previews(
    folder: Path, writes: FileWrites, gt: GroundTruth
) -> dict[str, tuple[str, dict[str, Any]]]:
    """One PNG per layer that has a preview maker, handed to *writes* as soon as it is drawn;
    return ``{layer: (path, encoding)}``."""
    (folder / PREVIEW_DIR).mkdir()
    previews: dict[str, tuple[str, dict[str, Any]]] = {}
    shown = shown_layers(gt.layers, gt.working_space)  # previews are sRGB
    for layer in shown.values():
        maker = preview_maker(layer)
        if maker is None:
            continue
        rel = preview_path(layer)
        rgb8, encoding = maker(layer, shown)
        writes.submit(rel, functools.partial(png.write_png, rgb8=rgb8))
        previews[layer.name] = (rel, encoding)
    return previews


def _write_meta(folder: Path, meta: dict[str, Any], hashes: Mapping[str, str]) -> None:
    """Write ``meta.json``: *meta* with the SHA-256 of every file it lists (*hashes*, as the
    file writes computed them, or read here) and its seal."""
    # meta.json last: its presence (with the right config hash) marks the folder complete; it
    # records the SHA-256 of every other file, so a resumed build can tell an intact sample,
    # and its own seal, so it can tell an intact meta.json
    files = meta["files"]
    meta[HASHES_KEY] = {rel: hashes.get(rel) or file_sha256(folder / rel) for rel in files}
    meta = plain_data(meta, META_DIGITS)
    meta[SEAL_KEY] = meta_seal(meta)
    _dump_json(folder / META_NAME, meta)


def _fill_folder(
    folder: Path,
    writes: FileWrites,
    scene: Scene,
    result: RenderResult,
    gt: GroundTruth,
    *,
    transport: LightTransport | None = None,
    cube: CubeFactors | None = None,
    sensor: SensorOutput | None = None,
    scene_folder: Path | None = None,
    **meta_kw: Any,
) -> dict[str, Any]:
    """Write (or hand to *writes*) every file of the sample but ``meta.json``; return
    ``meta.json``'s content without its hashes and seal."""
    coverage = result.aovs.get("coverage")
    files, storage = _write_layers(writes, gt, meta_kw["sample_id"], coverage, cube)
    if sensor is not None:  # the camera chain's raw DNG and processed PNG (gt_export.sensor)
        files += write_sensor_files(folder, sensor)
    previews = _write_previews(folder, writes, gt)
    files += [rel for rel, _ in previews.values()]
    # scene_to_dict, the record the scene hash is taken of (a procedural texture's recipe, not
    # its texel weights); scene_from_dict reads it back
    # its csv: names relative to the scene's folder, as every record of the sample holds them
    scene_record = portable_names(plain_data(scene_to_dict(scene)), scene_folder)
    scene_record = portable_map_files(scene_record, scene_folder)  # environment maps' files
    _dump_json(folder / SCENE_NAME, scene_record, compact=True)
    files.append(SCENE_NAME)
    record = None
    if transport is not None:  # the per-light transport, for exact relighting
        record = write_transport(
            folder, transport, result.aovs["coverage"], sample_id=meta_kw["sample_id"]
        )
        record["cameras"] = list(gt.cameras)  # full sensor-set names, to relight the camera layers
        files.append(TRANSPORT_NAME)
    meta = _meta(
        scene,
        result,
        gt,
        previews=previews,
        files=files,
        scene_record=scene_record,
        scene_folder=scene_folder,
        **meta_kw,
    )
    if record is not None:  # before the hashes and the seal, which cover it
        meta["transport"] = record
    meta["storage"] = storage
    if sensor is not None:
        meta["sensor"] = sensor.meta
        meta["identities"].append(sensor.identity)
    return portable_names(meta, scene_folder)  # csv: names of materials, lights and sensors


def export_sample(
    out_dir: str | os.PathLike[str],
    scene: Scene,
    result: RenderResult,
    settings: LayerSettings | None = None,
    *,
    sample_id: str,
    config: Mapping[str, Any],
    seed: int,
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
        A :class:`~spectrinsic.render.result.RenderResult` (arrays and metadata, never a live
        renderer).
    settings
        The layers to write (:class:`~spectrinsic.gt_export.layers.settings.LayerSettings`,
        default ``LayerSettings()``): cameras (default
        :data:`~spectrinsic.gt_export.layers.settings.DEFAULT_CAMERAS` when the render has the
        31-band cube, none otherwise), the cube, denoising, the per-band layers
        (``spectral.exr``, :mod:`~spectrinsic.gt_export.layers.spectral_intrinsics`), the
        working space (recorded in ``meta.json["working_space"]``), and a camera chain to run
        the sample through (:mod:`~spectrinsic.gt_export.sample.sensor`: raw mosaic, DNG,
        processed image and the ground truth in the processed linear space), its noise seeded
        from *seed* and ``settings.noise_id`` (default *sample_id*).
    sample_id
        Folder name, e.g. ``"obj-vase__v0__two-colour-a"``.
    config
        The settings the sample was built with; ``meta.json`` records :func:`config_hash` of it.
    seed
        The sample's render seed.
    transport
        A :class:`~spectrinsic.render.algebra.light_transport.LightTransport` of this render to store as
        ``transport.exr`` (:mod:`~spectrinsic.gt_export.sample.transport_exr`), for exact
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
    settings = settings or LayerSettings()
    settings = settings.with_cube("bands31" in result.raw)
    # with the transport stored, the cube is its stored means' sum (transport_cube), which
    # the readers rebuild bit for bit: every layer is computed from that cube
    cube = cube_factors(transport, scene, data_dir=settings.data_dir)
    result = with_cube(result, cube)
    gt = compute_ground_truth(scene, result, settings)
    sensor = None
    if settings.camera is not None:
        noise_id = settings.noise_id or sample_id
        sensor = sensor_output(
            gt, settings.camera, seed=seed, sample_id=noise_id, data_dir=settings.data_dir
        )
        gt = sensor.ground_truth
    final = out_dir / sample_id
    tmp = Path(tempfile.mkdtemp(prefix=f"{TMP_PREFIX}{sample_id}-", dir=out_dir))
    try:
        tmp.chmod(0o755)
        with FileWrites(tmp) as writes:  # EXR and PNG files encoded while the rest is computed
            meta = _fill_folder(
                tmp,
                writes,
                scene,
                result,
                gt,
                sample_id=sample_id,
                config=config,
                seed=seed,
                transport=transport,
                cube=cube,
                sensor=sensor,
                scene_folder=None if settings.scene_folder is None else Path(settings.scene_folder),
            )
            hashes = writes.hashes()
        _write_meta(tmp, meta, hashes)
        _move_into_place(tmp, final, config_hash(config))
    except WriteError as exc:  # named as the file will be (a full disk): not the temporary
        shutil.rmtree(tmp, ignore_errors=True)
        raise type(exc)(str(exc).replace(str(tmp), str(final))) from exc
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
    each matching its recorded SHA-256 (see :func:`~spectrinsic.gt_export.sample.integrity.sample_problem`)."""
    return sample_problem(sample_dir, config_hash) is None


def remove_sample_temporaries(out_dir: Path, sample_id: str) -> list[Path]:
    """Delete the temporaries :func:`export_sample` makes for *sample_id* in *out_dir* (its
    ``mkdtemp`` folder, an older version moved aside) that a killed run left; return them.

    Only folders named exactly as this module names them are touched; call it only while
    holding *out_dir*'s lock (no other writer can be using them then).
    """
    ours = re.compile(
        rf"{re.escape(TMP_PREFIX)}(?:{re.escape(sample_id)}-[a-z0-9_]{{8}}"
        rf"|old-{re.escape(sample_id)}-[0-9a-f]{{8}})"
    )
    stale = sorted(
        p
        for p in (out_dir.iterdir() if out_dir.is_dir() else ())
        if ours.fullmatch(p.name) and p.is_dir() and not p.is_symlink()
    )
    for path in stale:
        shutil.rmtree(path, ignore_errors=True)
    return stale
