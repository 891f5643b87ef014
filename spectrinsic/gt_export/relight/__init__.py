"""Exact relighting of a sample that stores its per-light transport (``dataset --store-transport``).

Every layer of a sample is a function of its raw band channels, and those are linear in every
light's band values (:mod:`spectrinsic.render.transport_render`, Eq. 1). So a sample under new light
spectra (and powers) is its transport composed with them (:func:`~spectrinsic.render.algebra.light_transport.relit_result`:
the raw channels batch by batch, the images once from the batches' mean), and every ground-truth layer is then
computed by :func:`~spectrinsic.gt_export.layers.compute_ground_truth` and written by
:func:`~spectrinsic.gt_export.sample.writer.export_sample`, the very functions that made the sample:
image and the 3-/6-sensor images, reflectance, shading, residual, illuminant, light shares,
camera layers, noise maps and the chapter-4 matrices, all for the new lights.

* Denoising: the relit white-surface radiance is denoised by OIDN as a rendered one is
  (same guides, normals and depth, same quality), not relit from a denoised one: a denoiser
  is not linear.
* Noise: the transport keeps the independent batches apart, so the relit sample's noise maps
  and ``meta.json["noise"]`` are measured from the spread of its own relit batches.
* Not relit: the spectral Monte Carlo image (it samples wavelengths; no band transport
  describes it) and direct-only renders; a relit sample has neither, so its
  ``meta.json["render"]`` holds no ``spectral_spp``/``spectral_batch_spp`` (its ``spp`` and
  ``batches`` are the transport's), and its ``relit`` record names the source sample (and
  the hash of its ``meta.json``, where the source's counts stand) and the new lights.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError, SceneError, SpectrinsicError
from ...number_lists import numbers_only
from ...render.algebra.light_transport import LightTransport, relit_result
from ...render.result import RenderResult
from ...scenes.model import Scene, scene_from_dict
from ...scenes.validate import POWER_RANGE
from ...spectra import get_spectrum
from ...spectra.user_spectra import readable_sensor_csv
from ..formats.exr import read_exr
from ..layers import LayerSettings
from ..layers.records import reference_mode
from ..sample import META_NAME, SCENE_NAME, file_sha256
from ..sample.integrity import replaceable_sample
from ..sample.meta import read_meta
from ..sample.sensor import model_from_meta
from ..sample.transport_exr import read_transport
from ..sample.working_view import space_of
from ..sample.writer import export_sample, remove_sample_temporaries
from .checks import (
    check_finite_result,
    check_relight_inputs,
    check_spectrum_files,
    readable_names,
)

__all__ = [
    "RelitSample",
    "read_sample_scene",
    "relit_scene",
    "relit_render",
    "relight",
    "check_light_spectra",
    "settings_of",
]

log = logging.getLogger(__name__)

#: AOV layers read back from ``geometry.exr`` (coverage comes from ``transport.exr``).
_AOV_LAYERS = ("depth", "normals", "material_id", "object_id", "mask")
#: Render metadata of the source that no longer describes a relit render: the spectral pass's
#: counts among them, as a relit sample holds no spectral image (its images are composed from
#: the transport, whose ``spp`` and ``batches`` the record keeps).
_DROPPED_META = (
    "direct_modes",
    "noise_target",
    "transport",
    "spectral_spp",
    "spectral_batch_spp",
)


@dataclasses.dataclass(frozen=True, eq=False)
class RelitSample:
    """A sample's scene and render under new lights, before its layers are computed.

    Attributes
    ----------
    scene
        The source scene with the new light spectra and powers.
    result
        The relit render (diagonal modes, per-light images, batches, AOVs).
    meta
        The source sample's ``meta.json``.
    transport
        The source sample's transport.
    """

    scene: Scene
    result: RenderResult
    meta: dict[str, Any]
    transport: LightTransport


def _fail(sample: Path, what: str) -> DatasetError:
    return DatasetError(f"{sample / SCENE_NAME}: {what}; not a scene spectrinsic wrote")


def _scene_record(sample: Path) -> Any:
    try:
        return json.loads((sample / SCENE_NAME).read_text(encoding="utf-8"))
    except OSError as exc:
        raise DatasetError(f"sample {str(sample)!r} has no readable {SCENE_NAME}") from exc
    except (ValueError, RecursionError) as exc:
        raise _fail(sample, f"not valid JSON ({exc})") from exc


def _csv_names(data: Any) -> set[str]:
    """Every ``csv:`` name in the plain data *data* (none in a list of plain numbers)."""
    if isinstance(data, str):
        return {data} if data[:4].lower() == "csv:" else set()
    if isinstance(data, list) and numbers_only(data):
        return set()
    values = data.values() if isinstance(data, dict) else data if isinstance(data, list) else ()
    return set().union(*(_csv_names(v) for v in values if isinstance(v, (str, dict, list))))


def read_sample_scene(
    sample_dir: str | os.PathLike[str], scene_dir: str | os.PathLike[str] | None = None
) -> Scene:
    """The :class:`Scene` a sample was rendered from, read from its ``scene.json``
    (:func:`~spectrinsic.scenes.model.scene_from_dict`, the inverse of the writer's
    :func:`~spectrinsic.scenes.model.scene_to_dict`), its ``csv:`` names (relative to the scene
    file's folder) resolved inside *scene_dir* (:func:`~.checks.readable_names`)."""
    sample = Path(sample_dir)
    return _scene_of(_scene_record(sample), sample, None if scene_dir is None else Path(scene_dir))


def _scene_of(record: Any, sample: Path, folder: Path | None) -> Scene:
    """The :class:`Scene` of *sample*'s parsed ``scene.json`` *record* (:func:`read_sample_scene`)."""
    data = readable_names(record, sample, folder)
    try:
        return scene_from_dict(data)
    except SceneError as exc:
        raise _fail(sample, str(exc).removeprefix("scene record: ")) from exc


def check_light_spectra(
    lights: Mapping[int, str], n_lights: int, *, data_dir: Any = None, what: str = "light"
) -> None:
    """Raise a one-line error unless every key is a light index below *n_lights* and every value
    names an illuminant of the spectra registry (with a did-you-mean for near misses)."""
    if not lights:
        raise DatasetError(f"{what}: expected at least one INDEX=SPECTRUM, e.g. 0=planck:3000K")
    for index, name in lights.items():
        if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < n_lights:
            raise DatasetError(f"{what} {index!r}={name}: the sample has lights 0..{n_lights - 1}")
        try:
            spectrum = get_spectrum(str(name), data_dir=data_dir)
        except SpectrinsicError as exc:
            raise DatasetError(f"{what} {index}={name}: {exc}") from None
        if spectrum.kind != "illuminant":
            raise DatasetError(
                f"{what} {index}={name}: a {spectrum.kind} spectrum; expected an illuminant "
                "(planck:3000K, cie:LED-RGB1, daylight:6500K, ...)"
            )


def relit_scene(
    scene: Scene,
    lights: Mapping[int, str],
    powers: Mapping[int, float] | None = None,
    *,
    source: str | None = None,
) -> Scene:
    """*scene* with light i's spectrum ``lights[i]`` (and power ``powers[i]``); others kept.
    Its metadata names the source sample and drops the energy ratio r (not relit)."""
    powers = dict(powers or {})
    lo, hi = POWER_RANGE  # the bounds of a scene file's powers: finite in float32 rendering
    bad = [i for i, p in powers.items() if not (isinstance(p, int | float) and lo <= p <= hi)]
    if bad:
        raise DatasetError(
            f"light power {powers[bad[0]]!r} for light {bad[0]}: expected a number in "
            f"[{lo:g}, {hi:g}]"
        )
    new = tuple(
        dataclasses.replace(
            li, spectrum=str(lights.get(i, li.spectrum)), power=float(powers.get(i, li.power))
        )
        for i, li in enumerate(scene.lights)
    )
    metadata = {k: v for k, v in scene.metadata.items() if k != "energy_ratio_r"}
    if source is not None:
        metadata["relit_from"] = source
    return dataclasses.replace(scene, lights=new, metadata=metadata)


def _render_meta(
    meta: Mapping[str, Any], transport: LightTransport, relit: Mapping[str, Any]
) -> dict[str, Any]:
    record = meta.get("render") or {}
    base = {k: v for k, v in record.items() if k not in _DROPPED_META}
    variants = base.get("variants") or {}
    base["variants"] = {m: v for m, v in variants.items() if m in transport.modes}
    base["relit"] = dict(relit)
    return base


def _aovs(sample: Path, meta: Mapping[str, Any], coverage: np.ndarray) -> dict[str, np.ndarray]:
    """The render's AOVs as they were: geometry layers from their EXR file (ids and mask back
    to their integer and boolean types, exactly: they are small integers stored as float32)."""
    records = meta.get("layers", {})
    out: dict[str, np.ndarray] = {}
    by_file: dict[str, list[str]] = {}
    for key in (k for k in _AOV_LAYERS if k in records):
        by_file.setdefault(records[key]["file"], []).append(key)
    for file, keys in by_file.items():
        arrays = read_exr(sample / file, layers=[records[k]["exr_layer"] for k in keys])
        out.update({k: arrays[records[k]["exr_layer"]] for k in keys})
    for key in ("material_id", "object_id"):
        if key in out:
            out[key] = np.rint(out[key]).astype(np.int32)
    if "mask" in out:
        out["mask"] = out["mask"] > 0.5
    out["coverage"] = coverage.astype(np.float32)
    return out


def _source_meta(sample: Path) -> dict[str, Any]:
    meta = dict(read_meta(sample).raw)  # SampleMetaError: one line naming the file and field
    if "transport" not in meta:
        raise DatasetError(
            f"sample {sample.name!r} stores no per-light transport; build it with "
            "`spectrinsic dataset --store-transport` to relight it"
        )
    return meta


def relit_render(
    sample_dir: str | os.PathLike[str],
    lights: Mapping[int, str],
    *,
    powers: Mapping[int, float] | None = None,
    data_dir: Any = None,
    scene_dir: str | os.PathLike[str] | None = None,
) -> RelitSample:
    """The sample's scene and render under new light spectra (and powers), in memory.

    Parameters
    ----------
    sample_dir
        A sample folder with ``transport.exr`` (``dataset --store-transport``).
    lights
        ``{light index: illuminant name}`` (``{0: "planck:3000K"}``); lights not named keep
        their spectrum. Names go through :func:`spectrinsic.spectra.get_spectrum`.
    powers
        ``{light index: power}`` to change brightness too (default: each light's own).
    scene_dir
        The folder of the scene file the sample was built from: the ``csv:`` spectra its
        records name relative to it are read (and verified) there; needed only by samples
        with such spectra.
    """
    sample = Path(sample_dir)
    meta = _source_meta(sample)
    n_lights = len(meta.get("lights", []))
    check_light_spectra(lights, n_lights, data_dir=data_dir)
    stray = [i for i in (powers or {}) if not (isinstance(i, int) and 0 <= i < n_lights)]
    if stray:
        raise DatasetError(f"--power {stray[0]!r}: the sample has lights 0..{n_lights - 1}")
    check_relight_inputs(sample, meta)  # every file read matches meta.json; the EXR's header
    folder = None if scene_dir is None else Path(scene_dir)
    record = _scene_record(sample)  # parsed once (110,000 values of mesh data in a room)
    used = _csv_names(record)  # as recorded: relative to the scene's folder
    used |= {c for c in settings_of(meta).cameras or () if c[:4].lower() == "csv:"}  # sensors
    check_spectrum_files(sample, meta, used, folder)  # CSVs read again: as at build time
    source = _scene_of(record, sample, folder)
    transport, coverage = read_transport(sample, meta["transport"])
    scene = relit_scene(source, lights, powers, source=str(meta["sample_id"]))
    relit = {
        "from": meta["sample_id"],
        "from_meta_sha256": file_sha256(sample / META_NAME),
        "lights": {str(i): li.spectrum for i, li in enumerate(scene.lights)},
        "powers": {str(i): li.power for i, li in enumerate(scene.lights)},
    }
    base = _render_meta(meta, transport, relit)
    dd = None if data_dir is None else str(data_dir)
    merged = relit_result(transport, scene, meta=base, data_dir=dd)
    _same_reference(sample, meta, merged)
    result = dataclasses.replace(merged, aovs=_aovs(sample, meta, coverage))
    return RelitSample(scene=scene, result=result, meta=meta, transport=transport)


def _same_reference(sample: Path, meta: Mapping[str, Any], relit: Any) -> None:
    """A relit sample keeps its base sample's reference mode, or relighting is refused: the
    preview preset's reference image is the ``spectral`` render, which the stored (diagonal)
    transport cannot give again, and a variant from another mode would not be comparable."""
    base, ref = meta.get("reference_mode"), reference_mode(relit)
    if base is not None and base != ref:
        raise DatasetError(
            f"SAMPLE {str(sample)!r}: its reference image is the {base!r} render, which the "
            f"stored transport cannot relight (it holds {', '.join(sorted(relit.images))}); "
            "relight samples of a preset whose reference mode is stored (the default preset)"
        )


def _empty_folder(path: Path) -> bool:
    return path.is_dir() and not path.is_symlink() and not any(path.iterdir())


def _check_out(sample: Path, out: Path) -> None:
    """``out`` must be a new folder or a sample spectrinsic wrote, and not the source."""
    if not out.name or out.name.startswith(".") or out.name in ("..",):
        raise DatasetError(f"--out {str(out)!r}: expected a folder name for the relit sample")
    if out.resolve() == sample.resolve():
        raise DatasetError(f"--out {str(out)!r} is the sample itself; choose a new folder")
    if (out.exists() or out.is_symlink()) and not _empty_folder(out):
        replaceable_sample(out)  # a sample spectrinsic wrote is replaced; anything else refused
    if out.parent.exists() and not out.parent.is_dir():
        raise DatasetError(f"--out {str(out)!r} lies below a file; expected a folder")


def relight(
    sample_dir: str | os.PathLike[str],
    lights: Mapping[int, str],
    out_dir: str | os.PathLike[str],
    *,
    powers: Mapping[int, float] | None = None,
    data_dir: Any = None,
    keep_transport: bool = False,
    scene_dir: str | os.PathLike[str] | None = None,
) -> Path:
    """Write *sample_dir* relit with new light spectra as a complete sample folder *out_dir*.

    The new folder is a sample like any other (``spectrinsic check`` verifies it; its
    ``meta.json`` keeps the source's config hash, so it may join the source's dataset), with
    every layer computed for the new lights from the stored transport (module notes). *out_dir*
    must be new, empty, or a sample folder spectrinsic wrote (then it is replaced); its name is
    the relit sample's id. *keep_transport* stores the transport again (the relit sample can
    then be relit itself; by default it is not copied, as relighting the source is the same).
    *scene_dir*: the scene file's folder, for a sample with ``csv:`` spectra
    (:func:`relit_render`); the relit sample names them relative to it too.

    Returns
    -------
    Path
        The relit sample folder.
    """
    sample, out = Path(sample_dir), Path(out_dir)
    _check_out(sample, out)
    for path in remove_sample_temporaries(out.parent, out.name):
        log.info("removed %s, left by a relight that was killed", path.name)
    relit = relit_render(sample, lights, powers=powers, data_dir=data_dir, scene_dir=scene_dir)
    check_finite_result(relit.result, sample)  # before anything is written
    meta = relit.meta
    if _empty_folder(out):
        out.rmdir()  # an empty --out is allowed, as for `dataset`; rmdir removes nothing else
    return export_sample(
        out.parent,
        relit.scene,
        relit.result,
        settings_of(meta, None if data_dir is None else str(data_dir), scene_dir).for_scene_folder(
            scene_dir
        ),
        sample_id=out.name,
        config={"config_hash": meta["config_hash"]},
        seed=int(meta["seed"]),
        transport=relit.transport if keep_transport else None,
    )


def settings_of(
    meta: Mapping[str, Any],
    data_dir: str | None = None,
    scene_dir: str | os.PathLike[str] | None = None,
) -> LayerSettings:
    """The :class:`LayerSettings` a sample was written with, from its ``meta.json``: its
    cameras (full sensor-set names, from the stored transport), cube, per-band layers,
    denoising, working space (``srgb`` for samples before issue 30) and camera chain, which
    re-runs on the relit image. The noise id is the sample's own id, so a relit sample's raw
    mosaic carries the noise of the source, not of the ``--out`` folder's name. A sensor CSV,
    recorded by its file name, is read from *scene_dir* (``None``: the working folder)."""
    layers = meta.get("layers", {})
    cameras = meta.get("transport", {}).get("cameras") or [
        f"camera:{c}" for c in meta.get("cameras", [])
    ]

    def readable(name: str) -> str:
        return readable_sensor_csv(name, scene_dir) if name[:4].lower() == "csv:" else name

    model = model_from_meta(meta)
    if model is not None:
        model = dataclasses.replace(model, sensitivities=readable(model.sensitivities))
    return LayerSettings(
        cameras=tuple(readable(c) for c in cameras),
        camera=model,
        write_cube="cube" in layers,
        denoise=bool(meta.get("denoised_layers")),
        spectral_layers="shading_bands" in layers,
        working_space=space_of(meta),
        data_dir=data_dir,
        noise_id=str(meta["sample_id"]),
    )
