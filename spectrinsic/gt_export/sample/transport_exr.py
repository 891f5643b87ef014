"""The per-light transport of a sample on disk: ``transport.exr`` and its ``meta.json`` record.

One OpenEXR file, ZIPS-compressed (lossless zlib per scanline), in the *compact* layout (issue 45; :data:`COMPACT_LAYOUT`) holds

* ``L<l>_<mode>``: the batch mean of the transport ``T_lk`` of light ``l`` for each
  relightable render mode (float32; channels named after the mode's sensors: ``B400`` ...
  ``B700`` for ``bands31``, ``X, Y, Z`` for ``rgb3``, ``G425`` ... for ``rgb6``): the raw channels
  ``∫ radiance · S_k dλ`` (render units) light ``l`` alone gives with the flat unit spectrum
  ``L(λ) = 1`` at power 1 (:mod:`spectrinsic.render.transport_render`, Eq. 1);
* ``D<l>_b<b>_<mode>`` for the batches ``b < B - 1`` of a sample rendered in ``B >= 2``
  independent batches: batch ``b``'s deviation from that mean, ``T_lk,b - T̄_lk``, divided by
  ``2^e`` (``e`` per layer in the record's ``deviation_exponents``, a power of two, so the
  scaling is exact) and stored as float16. The last batch's deviation is minus the sum of the
  others'. The deviations only feed the sample's noise estimate (the batches' spread), which
  is part of no identity; the mean, which every layer is composed from, is float32;
* for scenes with glossy materials, ``S<l>_<mode>``: the batch mean of the part of that
  transport whose first camera-ray vertex went through a non-diffuse lobe (the ``specular``
  layer's), and with metals ``W<l>_<mode>``: the white-surface radiance at metal first hits
  (the metals' ``shading``), both for the same unit spectrum
  (:mod:`spectrinsic.render.band_path.kernel`);
* ``coverage``: ``(H, W, M)`` fraction of each pixel's samples hitting material ``m`` (the
  reflectance and the white-surface radiance are built from it, and it cannot be recovered
  from the reflectance).

Samples written before issue 45 hold every batch in full, uncompressed (``L<l>_b<b>_<mode>``,
``S<l>_b<b>_<mode>``, ...; their record has no ``layout``); they still load.

``meta.json["transport"]`` records the file, its layout, the layer patterns, modes and their
sensors, the number of lights and batches, each batch's seed and samples per pixel, the glossy
parts held (``parts``), the units and the file's size in bytes.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...render.algebra.batch_means import batch_mean
from ...render.algebra.light_transport import LightTransport
from ...render.result import PARTS
from ...spectra import get_sensors
from ..formats.exr import read_exr_stacks, write_exr
from . import TRANSPORT_NAME

__all__ = [
    "TRANSPORT_NAME",
    "COVERAGE_LAYER",
    "COMPACT_LAYOUT",
    "TRANSPORT_COMPRESSION",
    "deviation_layer",
    "is_compact",
    "stored_layers",
    "transport_layer",
    "write_transport",
    "read_transport",
]

COVERAGE_LAYER = "coverage"
#: The layout of :func:`write_transport` (``meta.json["transport"]["layout"]``); a record
#: without a layout is the per-batch layout of samples written before issue 45.
COMPACT_LAYOUT = "batch-mean+half-deviations"
#: The EXR compression of ``transport.exr`` (:data:`~spectrinsic.gt_export.formats.exr.COMPRESSIONS`):
#: zlib per scanline, as small as ``"zip"`` on Monte Carlo noise and 4x faster to read back.
TRANSPORT_COMPRESSION = "zips"
#: The letter of the batch deviations' layers (a part's letters are in :data:`~spectrinsic.render.result.PARTS`).
DEVIATION_LETTER = "D"
#: The largest float16 magnitude a deviation is scaled to: 2^14, below float16's 65504, so
#: a scaled deviation never overflows and keeps 11 significant bits down to 2^-14 of it.
_HALF_TOP_EXPONENT = 14
TRANSPORT_UNITS = (
    "raw channel ∫ radiance · S_k dλ (render units) of one light alone emitting the "
    "flat unit spectrum L(λ) = 1 at power 1; raw_k = Σ_l T_lk · power_l ∫L_l S_k dλ / ∫S_k dλ"
)


def transport_layer(light: int, batch: int | None, mode: str, part: str = "transport") -> str:
    """EXR layer name of light *light*'s transport (or its *part*, :data:`~spectrinsic.render.result.PARTS`) for
    *mode*: the batch mean (*batch* ``None``, the compact layout) or batch *batch* (the layout
    before issue 45).

    >>> transport_layer(1, None, "bands31"), transport_layer(0, 1, "rgb3", "specular")
    ('L1_bands31', 'S0_b1_rgb3')
    """
    letter = "L" if part == "transport" else PARTS[part]
    batch_tag = "" if batch is None else f"_b{int(batch)}"
    return f"{letter}{int(light)}{batch_tag}_{mode}"


def deviation_layer(light: int, batch: int, mode: str) -> str:
    """EXR layer name of batch *batch*'s scaled float16 deviation from the mean transport.

    >>> deviation_layer(2, 0, "rgb6")
    'D2_b0_rgb6'
    """
    return f"{DEVIATION_LETTER}{int(light)}_b{int(batch)}_{mode}"


def _parts(transport: LightTransport) -> dict[str, tuple[dict[str, np.ndarray], ...]]:
    """The transport's batches and each glossy part it holds, by part name."""
    held = {"transport": transport.batches}
    held.update({p: transport.parts[p] for p in PARTS if transport.parts.get(p)})
    return held


def _scaled_half(deviation: np.ndarray) -> tuple[np.ndarray, int]:
    """*deviation* divided by ``2^e`` as float16, and ``e``: its largest magnitude lands in
    ``[2^13, 2^14)``, so nothing overflows; a power of two divides exactly."""
    top = float(np.max(np.abs(deviation), initial=0.0))
    exponent = int(np.frexp(top)[1]) - _HALF_TOP_EXPONENT if top > 0 else 0
    return np.ldexp(deviation, -exponent).astype(np.float16), exponent


def _compact_layers(
    transport: LightTransport,
) -> tuple[dict[str, np.ndarray], dict[str, int]]:
    """The mean layers of every part and the scaled deviations of the transport's batches
    (all but the last batch), with the deviations' exponents."""
    layers: dict[str, np.ndarray] = {}
    exponents: dict[str, int] = {}
    n = len(transport.batches)
    for part, batches in _parts(transport).items():
        for mode in transport.modes:
            mean = batch_mean([b[mode] for b in batches])
            for light in range(transport.n_lights):
                layers[transport_layer(light, None, mode, part)] = mean[light]
            if part != "transport" or n < 2:
                continue  # the parts' spread feeds nothing; one batch has none
            for b in range(n - 1):
                deviation = batches[b][mode].astype(np.float64) - mean
                for light in range(transport.n_lights):
                    key = deviation_layer(light, b, mode)
                    layers[key], exponents[key] = _scaled_half(deviation[light])
    return layers, exponents


def write_transport(
    folder: str | os.PathLike[str],
    transport: LightTransport,
    coverage: np.ndarray,
    *,
    sample_id: str,
) -> dict[str, Any]:
    """Write ``transport.exr`` into *folder* in the compact layout; return its
    ``meta.json["transport"]`` record."""
    layers, exponents = _compact_layers(transport)
    layers[COVERAGE_LAYER] = np.asarray(coverage, np.float32)
    names: dict[str, tuple[str, ...]] = {
        COVERAGE_LAYER: tuple(f"m{m}" for m in range(np.shape(coverage)[-1]))
    }
    for key in layers:
        if key != COVERAGE_LAYER:
            mode = key.rsplit("_", 1)[1]
            names[key] = get_sensors(transport.sensors[mode]).channels
    path = Path(folder) / TRANSPORT_NAME
    write_exr(
        path,
        layers,
        channel_names=names,
        attributes={"spectrinsic.sample": sample_id},
        half=tuple(exponents),
        compression=TRANSPORT_COMPRESSION,
    )
    return {
        "file": TRANSPORT_NAME,
        "layout": COMPACT_LAYOUT,
        "layers": "L<light>_<mode> (batch mean); D<light>_b<batch>_<mode> (deviation / 2^e)",
        "coverage_layer": COVERAGE_LAYER,
        "modes": list(transport.modes),
        "sensors": dict(transport.sensors),
        "lights": transport.n_lights,
        "batches": len(transport.batches),
        "batch_seeds": list(transport.seeds),
        "batch_spp": transport.batch_spp,
        "max_depth": transport.max_depth,
        "parts": [p for p in _parts(transport) if p in PARTS],
        "deviation_exponents": exponents,
        "units": TRANSPORT_UNITS,
        "dtype": "float32 (deviations float16)",
        "compression": TRANSPORT_COMPRESSION,
        "bytes": path.stat().st_size,
    }


def _field(record: Any, key: str, kind: type | tuple[type, ...], where: str) -> Any:
    value = record.get(key) if isinstance(record, dict) else None
    if not isinstance(value, kind) or isinstance(value, bool):
        raise DatasetError(f"{where}: meta.json transport.{key} is missing or malformed")
    return value


def is_compact(record: Any) -> bool:
    """Whether a ``meta.json["transport"]`` *record* is of the compact layout (else the
    per-batch layout before issue 45; any other layout is refused)."""
    layout = record.get("layout") if isinstance(record, dict) else None
    if layout not in (None, COMPACT_LAYOUT):
        raise DatasetError(
            f"meta.json transport layout {layout!r} is unknown; expected {COMPACT_LAYOUT!r} "
            "(rebuild the sample with this version of spectrinsic)"
        )
    return layout == COMPACT_LAYOUT


def stored_layers(record: Any, lights: int, batches: int) -> dict[tuple[str, int, str], list[str]]:
    """``{(part, batch, mode): [layer of each light]}`` of a transport record: every batch's
    own layers (per-batch layout), or the mean's (compact: batch ``-1``) and each stored
    deviation's (part ``"deviation"``)."""
    modes = record["modes"]
    parts = ["transport", *record.get("parts", [])]
    if not is_compact(record):
        return {
            (part, b, mode): [transport_layer(j, b, mode, part) for j in range(lights)]
            for part in parts
            for b in range(batches)
            for mode in modes
        }
    layers = {
        (part, -1, mode): [transport_layer(j, None, mode, part) for j in range(lights)]
        for part in parts
        for mode in modes
    }
    deviations = range(batches - 1 if batches > 1 else 0)
    layers.update(
        {
            ("deviation", b, mode): [deviation_layer(j, b, mode) for j in range(lights)]
            for b in deviations
            for mode in modes
        }
    )
    return layers


def read_transport(
    sample_dir: str | os.PathLike[str], record: Any
) -> tuple[LightTransport, np.ndarray]:
    """The transport and the ``(H, W, M)`` coverage stored in a sample (its ``meta.json``
    ``transport`` *record*), checked against the record before use. In the compact layout the
    batches are the mean plus each deviation (the last: the mean minus their sum), and every
    part's batches are its mean."""
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
    layers = stored_layers(record, lights, len(seeds))
    # the stacks' names: "<part>/<batch>/<mode>" and the coverage layer's (which has no "/")
    named = {_key(k): v for k, v in layers.items()} | {COVERAGE_LAYER: [COVERAGE_LAYER]}
    stacks = read_exr_stacks(folder / TRANSPORT_NAME, named)
    if is_compact(record):
        exponents = _exponents(record, layers, where)
        held = _batches_from_compact(stacks, exponents, ["transport", *parts], modes, len(seeds))
    else:
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
        batch_spp=_field(record, "batch_spp", int, where),
        max_depth=_field(record, "max_depth", int, where),
        parts={p: held[p] for p in PARTS if p in held},
    )
    return transport, coverage


def _exponents(
    record: Any, layers: dict[tuple[str, int, str], list[str]], where: str
) -> dict[str, int]:
    """The record's ``deviation_exponents``, one integer per stored deviation layer, each a
    power of two float32 holds (``2^-149`` ... ``2^127``)."""
    exponents = record.get("deviation_exponents")
    wanted = {name for k, names in layers.items() if k[0] == "deviation" for name in names}
    if (
        not isinstance(exponents, dict)
        or set(exponents) != wanted
        or any(type(e) is not int or not -149 <= e <= 127 for e in exponents.values())
    ):
        raise DatasetError(
            f"{where}: meta.json transport.deviation_exponents is missing or malformed"
        )
    return exponents


def _batches_from_compact(
    stacks: dict[str, np.ndarray],
    exponents: dict[str, int],
    parts: list[str],
    modes: list[str],
    n: int,
) -> dict[str, tuple[dict[str, np.ndarray], ...]]:
    """Every part's batches from the compact layers: the transport's batch ``b`` is the mean
    plus its deviation times ``2^e`` (float32), the last the mean minus the others'; a part's
    batches are its mean."""
    held: dict[str, tuple[dict[str, np.ndarray], ...]] = {}
    for part in parts:
        means = {mode: stacks[_key((part, -1, mode))] for mode in modes}
        if part != "transport" or n < 2:
            held[part] = tuple(means for _ in range(n))
            continue
        batches: list[dict[str, np.ndarray]] = [{} for _ in range(n)]
        for mode in modes:
            deviations = [
                _unscaled(stacks[_key(("deviation", b, mode))], exponents, mode, b)
                for b in range(n - 1)
            ]
            last = -np.sum(deviations, axis=0, dtype=np.float32)
            for b, deviation in enumerate([*deviations, last]):
                deviation += means[mode]  # in place: the batch, float32
                batches[b][mode] = deviation
        held[part] = tuple(batches)
    return held


def _unscaled(stack: np.ndarray, exponents: dict[str, int], mode: str, batch: int) -> np.ndarray:
    """A ``(L, H, W, K)`` deviation stack times each light's ``2^e`` in place (float32: a
    float16 value times a power of two is exact there)."""
    for j in range(stack.shape[0]):
        stack[j] *= np.float32(2.0 ** exponents[deviation_layer(j, batch, mode)])
    return stack


def _key(layer: tuple[str, int, str]) -> str:
    """The name of one (part, batch, mode) stack of :func:`read_transport`."""
    part, batch, mode = layer
    return f"{part}/{batch}/{mode}"
