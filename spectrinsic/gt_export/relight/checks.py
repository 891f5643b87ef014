"""What ``relight`` reads, checked before it is used (issue 36, cause 3).

A relit sample is written with fresh SHA-256s, so a damaged source relit without checks would
be laundered: ``check`` could no longer find the damage. Before anything is decoded:

* every file the relighting reads (``scene.json``, ``transport.exr`` and the files holding the
  AOV layers) must be listed in the sample's sealed ``meta.json`` and match its SHA-256 there
  (``meta.json`` itself is checked against its seal by
  :func:`~spectrinsic.gt_export.sample.meta.read_meta`);
* the transport's EXR header must declare the sample's image size and exactly the channels its
  ``meta.json["transport"]`` record implies (a light's transport per batch, mode and part, each
  with its sensors' channels, and the coverage's ``m0`` ... ``m<M-1>``), so a file that would
  decode to something else is refused from its header alone.

The spectra the relighting reads again from files (``csv:`` names of the scene's materials and
lights, read when the layers are computed) must be listed in ``meta.json["spectrum_files"]``
and match the SHA-256 recorded there (:func:`check_spectrum_files`): an edited CSV would
otherwise change every layer of the relit sample with rc 0. A sample names those files relative
to its scene file's folder (no written file holds a path of the machine that built it), so
relighting one needs that folder (``relight --scene-dir``, ``scene_dir=``): the names resolve
inside it only, as a scene file's do (:func:`readable_names`); a sample written before names
were portable records absolute paths, read as they are. A scene holds no other external
file: its meshes and texture weights are in ``scene.json``, its lights' SPDs in ``meta.json``.

After composing, :func:`check_finite_result` refuses a relit render holding a NaN or an
infinity (powers that overflow float32) before anything is written.

Each refusal is one line naming the file.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError, SpectrinsicError
from ...number_lists import copy_numbers, numbers_only
from ...render.result import RenderResult
from ...scenes.spectrum_refs import confined_csv
from ...spectra import get_sensors
from ...spectra.user_spectra import readable_sensor_csv, split_csv_key
from ..formats.exr import read_exr_attributes
from ..sample import META_NAME, SCENE_NAME, file_sha256
from ..sample.transport_exr import COVERAGE_LAYER, TRANSPORT_NAME, stored_layers

__all__ = [
    "verified_file",
    "check_spectrum_files",
    "readable_names",
    "transport_channels",
    "check_transport_header",
    "check_relight_inputs",
    "check_finite_result",
]

#: AOV layers relighting reads back from the sample (their files come from ``meta.json``).
AOV_LAYERS = ("depth", "normals", "material_id", "object_id", "mask")


def verified_file(sample: Path, meta: Mapping[str, Any], file: str) -> Path:
    """``sample / file`` after checking it against its SHA-256 in ``meta.json["sha256"]``."""
    path = sample / file
    hashes = meta.get("sha256")
    expected = hashes.get(file) if isinstance(hashes, Mapping) else None
    if expected is None:
        raise DatasetError(f"{path}: not listed with a SHA-256 in {META_NAME}; cannot verify it")
    if not path.is_file():
        raise DatasetError(f"{path}: listed in {META_NAME} but missing; the sample is incomplete")
    if file_sha256(path) != expected:
        raise DatasetError(
            f"{path}: does not match its SHA-256 in {META_NAME}; the sample is damaged "
            "(spectrinsic check finds every such file); refusing to relight it"
        )
    return path


def transport_channels(record: Mapping[str, Any]) -> set[str]:
    """The channel names (``"L0_rgb3.X"``; ``"L0_b1_rgb3.X"`` in the per-batch layout before
    issue 45) a transport record implies, coverage excluded."""
    try:
        layers = stored_layers(record, int(record["lights"]), len(record["batch_seeds"]))
        channels = {m: get_sensors(record["sensors"][m]).channels for m in record["modes"]}
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise DatasetError(f"{META_NAME} transport record is malformed ({exc})") from None
    return {
        f"{name}.{c}"
        for (_, _, mode), names in layers.items()
        for name in names
        for c in channels[mode]
    }


def _names(channels: Iterable[Any]) -> list[str]:
    return [str(getattr(c, "name", c)) for c in channels]


def check_transport_header(path: Path, record: Mapping[str, Any], size: tuple[int, int]) -> None:
    """Refuse ``transport.exr`` unless its header declares *size* ``(height, width)`` and
    exactly the channels of *record* plus a contiguous coverage ``m0`` ... ``m<M-1>``."""
    header = read_exr_attributes(path)
    try:
        (x0, y0), (x1, y1) = (tuple(int(v) for v in p) for p in header["dataWindow"])  # type: ignore[attr-defined]
        names = _names(header["channels"])  # type: ignore[arg-type]
    except (KeyError, TypeError, ValueError) as exc:
        raise DatasetError(f"{path}: unreadable header ({exc}); not a transport file") from None
    declared = (y1 - y0 + 1, x1 - x0 + 1)
    if declared != tuple(size):
        raise DatasetError(
            f"{path}: declares {declared[1]}x{declared[0]} pixels; the sample is "
            f"{size[1]}x{size[0]}"
        )
    coverage = sorted(n for n in names if n.startswith(f"{COVERAGE_LAYER}."))
    pattern = re.compile(rf"^{COVERAGE_LAYER}\.m(\d+)$")
    indices = sorted(int(m.group(1)) for n in coverage if (m := pattern.match(n)))
    expected = transport_channels(record)
    if (
        not coverage
        or indices != list(range(len(coverage)))
        or set(names) - set(coverage) != expected
    ):
        extra = sorted(set(names) - set(coverage) - expected)[:3]
        missing = sorted(expected - set(names))[:3]
        raise DatasetError(
            f"{path}: holds {len(names)} channels, not those its {META_NAME} record implies "
            f"({len(expected)} transport channels and a coverage; missing {missing}, "
            f"unexpected {extra})"
        )


def check_relight_inputs(sample: Path, meta: Mapping[str, Any]) -> None:
    """Verify every file relighting *sample* reads against *meta* (its parsed, sealed
    ``meta.json``), then the transport's header; a one-line :class:`DatasetError` otherwise."""
    record = meta["transport"]
    transport_file = record.get("file") if isinstance(record, Mapping) else None
    if transport_file != TRANSPORT_NAME:
        raise DatasetError(f"{sample / META_NAME}: transport record is not spectrinsic's")
    layers = meta.get("layers") or {}
    aov_files = {layers[k]["file"] for k in AOV_LAYERS if k in layers}
    for file in [SCENE_NAME, TRANSPORT_NAME, *sorted(aov_files)]:
        verified_file(sample, meta, file)
    size = meta.get("size")
    if not (isinstance(size, list) and len(size) == 2):
        raise DatasetError(f"{sample / META_NAME}: size {size!r}; expected [height, width]")
    check_transport_header(sample / TRANSPORT_NAME, record, (int(size[0]), int(size[1])))


def _readable_csv(sample: Path, name: str, scene_dir: Path | None) -> str:
    """The recorded ``csv:`` *name* with a path the process can read: a relative one resolved
    inside *scene_dir* (:func:`~spectrinsic.scenes.spectrum_refs.confined_csv`), an absolute
    one (a sample from before portable names) as it is; a camera's sensor CSV in *scene_dir*
    or else the working folder (:func:`~spectrinsic.spectra.user_spectra.readable_sensor_csv`)."""
    if "#" not in name:  # a camera's sensor set, named by its file name (no column)
        return readable_sensor_csv(name, scene_dir)
    path, _ = split_csv_key(name.strip()[4:])
    if Path(path).is_absolute():
        return name
    if scene_dir is None:
        raise DatasetError(
            f"{sample / SCENE_NAME}: spectrum {name!r} is read from a file relative to the "
            "scene file's folder; give that folder (relight --scene-dir DIR)"
        )
    try:
        return confined_csv(name, scene_dir)
    except SpectrinsicError as exc:
        raise DatasetError(f"--scene-dir {str(scene_dir)!r}: spectrum {name!r}: {exc}") from None


def readable_names(data: Any, sample: Path, scene_dir: Path | None) -> Any:
    """A copy of the scene record *data* (``scene.json``) with every ``csv:`` name made
    readable (:func:`_readable_csv`), so the registry reads the files the sample names; lists of
    plain numbers (a mesh's) copied whole (:mod:`~spectrinsic.number_lists`)."""
    if isinstance(data, str):
        return _readable_csv(sample, data, scene_dir) if data[:4].lower() == "csv:" else data
    if isinstance(data, dict):
        return {k: readable_names(v, sample, scene_dir) for k, v in data.items()}
    if isinstance(data, list):
        if numbers_only(data):
            return copy_numbers(data)
        return [readable_names(v, sample, scene_dir) for v in data]
    return data


def check_spectrum_files(
    sample: Path, meta: Mapping[str, Any], names: Iterable[str], scene_dir: Path | None = None
) -> None:
    """Refuse unless every ``csv:`` spectrum among *names* (the source scene's, as recorded) is
    listed in ``meta["spectrum_files"]`` and its file (relative names: in *scene_dir*) still
    matches the SHA-256 recorded there."""
    records = meta.get("spectrum_files") or []
    listed = {
        r.get("spectrum"): r
        for r in records
        if isinstance(records, list) and isinstance(r, Mapping)
    }
    for name in sorted({n for n in names if n.lower().startswith("csv:")}):
        record = listed.get(name)
        if record is None or not isinstance(record.get("file"), str):
            raise DatasetError(
                f"{sample / META_NAME}: spectrum {name!r} is read from a file that "
                "spectrum_files does not list with a SHA-256; cannot verify it"
            )
        readable = _readable_csv(sample, name, scene_dir)[4:]
        path = Path(split_csv_key(readable)[0] if "#" in name else readable.strip())
        if not path.is_file():
            raise DatasetError(
                f"{path}: the spectrum file of {name!r} listed in {sample / META_NAME} is missing"
            )
        if file_sha256(path) != record.get("sha256"):
            raise DatasetError(
                f"{path}: does not match its SHA-256 in {sample / META_NAME} (spectrum_files); "
                "the spectra changed since the sample was built; refusing to relight it"
            )


def check_finite_result(result: RenderResult, sample: Path) -> None:
    """Refuse a relit render whose images or raw channels hold a NaN or an infinity."""
    for what, arrays in (("image", result.images), ("raw channels", result.raw)):
        for mode, array in arrays.items():
            if not np.isfinite(array).all():
                raise DatasetError(
                    f"{sample}: relit {what} of mode {mode!r} is not finite (the new lights "
                    "overflow float32); nothing written"
                )
