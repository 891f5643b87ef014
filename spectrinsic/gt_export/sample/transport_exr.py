"""The per-light transport of a sample on disk: ``transport.exr`` and its ``meta.json`` record.

One float32 OpenEXR file (uncompressed: ZIP cannot shrink Monte Carlo noise) holds

* ``L<l>_b<b>_<mode>``: the transport ``T_lk`` of light ``l`` in independent batch ``b`` for
  each relightable render mode (channels named after the mode's sensors: ``B400`` ... ``B700``
  for ``bands31``, ``X, Y, Z`` for ``rgb3``, ``G425`` ... for ``rgb6``): the raw channels
  ``∫ radiance · S_k dλ`` (render units) light ``l`` alone gives with the flat unit spectrum
  ``L(λ) = 1`` at power 1 (:mod:`spectrinsic.render.transport_render`, Eq. 1);
* for scenes with glossy materials, ``S<l>_b<b>_<mode>``: the part of that transport whose
  first camera-ray vertex went through a non-diffuse lobe (the ``specular`` layer's), and with
  metals ``W<l>_b<b>_<mode>``: the white-surface radiance at metal first hits (the metals'
  ``shading``), both for the same unit spectrum (:mod:`spectrinsic.render.band_path.kernel`);
* ``coverage``: ``(H, W, M)`` fraction of each pixel's samples hitting material ``m`` (the
  reflectance and the white-surface radiance are built from it, and it cannot be recovered
  from the reflectance).

``meta.json["transport"]`` records the file, the layer pattern, modes and their sensors, the
number of lights and batches, each batch's seed and samples per pixel, the glossy parts held
(``parts``), the units and the file's size in bytes. The batches are kept apart because the sample's noise estimate is their spread.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...render.algebra.light_transport import LightTransport
from ...render.band_path.traversal import PARTS as TRAVERSAL_PARTS
from ...spectra import get_sensors
from ..formats.exr import read_exr_stacks, write_exr
from . import TRANSPORT_NAME

__all__ = [
    "TRANSPORT_NAME",
    "COVERAGE_LAYER",
    "transport_layer",
    "write_transport",
    "read_transport",
]

COVERAGE_LAYER = "coverage"
TRANSPORT_UNITS = (
    "raw channel ∫ radiance · S_k dλ (render units) of one light alone emitting the "
    "flat unit spectrum L(λ) = 1 at power 1; raw_k = Σ_l T_lk · power_l ∫L_l S_k dλ / ∫S_k dλ"
)


#: Glossy parts of the transport, and the letter their layers start with (the transport's: L);
#: their one home is the traversal's (:data:`spectrinsic.render.band_path.traversal.PARTS`).
PARTS = TRAVERSAL_PARTS


def transport_layer(light: int, batch: int, mode: str, part: str = "transport") -> str:
    """EXR layer name of light *light*'s transport (or its glossy *part*, :data:`PARTS`) in
    batch *batch* for *mode*.

    >>> transport_layer(1, 0, "bands31"), transport_layer(0, 1, "rgb3", "specular")
    ('L1_b0_bands31', 'S0_b1_rgb3')
    """
    letter = "L" if part == "transport" else PARTS[part]
    return f"{letter}{int(light)}_b{int(batch)}_{mode}"


def _parts(transport: LightTransport) -> dict[str, tuple[dict[str, np.ndarray], ...]]:
    """The transport's batches and each glossy part it holds, by part name."""
    held = {"transport": transport.batches}
    held.update({p: transport.parts[p] for p in PARTS if transport.parts.get(p)})
    return held


def write_transport(
    folder: str | os.PathLike[str],
    transport: LightTransport,
    coverage: np.ndarray,
    *,
    sample_id: str,
) -> dict[str, Any]:
    """Write ``transport.exr`` into *folder*; return its ``meta.json["transport"]`` record."""
    layers: dict[str, np.ndarray] = {COVERAGE_LAYER: np.asarray(coverage, np.float32)}
    names: dict[str, tuple[str, ...]] = {
        COVERAGE_LAYER: tuple(f"m{m}" for m in range(np.shape(coverage)[-1]))
    }
    for part, batches in _parts(transport).items():
        for b, batch in enumerate(batches):
            for mode in transport.modes:
                channels = get_sensors(transport.sensors[mode]).channels
                for light in range(transport.n_lights):
                    key = transport_layer(light, b, mode, part)
                    layers[key] = batch[mode][light]
                    names[key] = channels
    path = Path(folder) / TRANSPORT_NAME
    write_exr(
        path,
        layers,
        channel_names=names,
        attributes={"spectrinsic.sample": sample_id},
        compressed=False,  # Monte Carlo noise: ZIP saved 12 % and tripled the relight's read
    )
    return {
        "file": TRANSPORT_NAME,
        "layers": "L<light>_b<batch>_<mode>",
        "coverage_layer": COVERAGE_LAYER,
        "modes": list(transport.modes),
        "sensors": dict(transport.sensors),
        "lights": transport.n_lights,
        "batches": len(transport.batches),
        "batch_seeds": list(transport.seeds),
        "batch_spp": transport.spp,
        "max_depth": transport.max_depth,
        "parts": [p for p in _parts(transport) if p in PARTS],
        "units": TRANSPORT_UNITS,
        "dtype": "float32",
        "bytes": path.stat().st_size,
    }


def _field(record: Any, key: str, kind: type | tuple[type, ...], where: str) -> Any:
    value = record.get(key) if isinstance(record, dict) else None
    if not isinstance(value, kind) or isinstance(value, bool):
        raise DatasetError(f"{where}: meta.json transport.{key} is missing or malformed")
    return value


def read_transport(
    sample_dir: str | os.PathLike[str], record: Any
) -> tuple[LightTransport, np.ndarray]:
    """The transport and the ``(H, W, M)`` coverage stored in a sample (its ``meta.json``
    ``transport`` *record*), checked against the record before use."""
    folder = Path(sample_dir)
    where = str(folder)
    modes = _field(record, "modes", list, where)
    sensors = _field(record, "sensors", dict, where)
    lights = _field(record, "lights", int, where)
    seeds = _field(record, "batch_seeds", list, where)
    if (
        _field(record, "file", str, where) != TRANSPORT_NAME
        or not modes
        or set(sensors) != set(modes)
    ):
        raise DatasetError(f"{where}: meta.json transport record is not spectrinsic's")
    parts = record.get("parts", []) if isinstance(record, dict) else []
    if not isinstance(parts, list) or any(p not in PARTS for p in parts):
        raise DatasetError(
            f"{where}: meta.json transport parts {parts!r}; expected some of {list(PARTS)}"
        )
    path = folder / TRANSPORT_NAME
    layers = {
        (part, b, mode): [transport_layer(j, b, mode, part) for j in range(lights)]
        for part in ["transport", *parts]
        for b in range(len(seeds))
        for mode in modes
    }
    # the stacks' names: "<part>/<batch>/<mode>" and the coverage layer's (which has no "/")
    named = {_key(k): v for k, v in layers.items()} | {COVERAGE_LAYER: [COVERAGE_LAYER]}
    stacks = read_exr_stacks(path, named)
    held = {
        part: tuple(
            {mode: stacks[_key((part, b, mode))] for mode in modes} for b in range(len(seeds))
        )
        for part in ["transport", *parts]
    }
    coverage = stacks[COVERAGE_LAYER][0]
    transport = LightTransport(
        modes=tuple(modes),
        sensors={str(k): str(v) for k, v in sensors.items()},
        batches=held["transport"],
        seeds=tuple(int(s) for s in seeds),
        spp=_field(record, "batch_spp", int, where),
        max_depth=_field(record, "max_depth", int, where),
        parts={p: held[p] for p in PARTS if p in held},
    )
    return transport, coverage


def _key(layer: tuple[str, int, str]) -> str:
    """The name of one (part, batch, mode) stack of :func:`read_transport`."""
    part, batch, mode = layer
    return f"{part}/{batch}/{mode}"
