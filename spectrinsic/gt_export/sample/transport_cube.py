"""The 31-band cube of a sample that stores its transport, *defined* from the transport as
stored (issue 45), so the readers rebuild it bit for bit from ``transport.exr`` and the sample
need not hold it a second time.

A sample written with its transport takes as its rendered cube (``image_bands_raw``, or
``image_bands`` where it is not denoised)

    cube_k = Σ_l float32(T̄_lk ∘ float32(ē_lk))     (Eq. 1 of :mod:`~spectrinsic.render.transport_render`)

with ``T̄_lk`` the float32 batch mean written as ``L<l>_bands31`` in ``transport.exr``
(:func:`~spectrinsic.render.algebra.batch_means.batch_mean`, the very values the file holds)
and ``ē_lk`` the lights' band means (:func:`~spectrinsic.render.algebra.light_transport.light_band_means`),
composed by :func:`~spectrinsic.render.algebra.shares.compose`: elementwise products, the
lights summed in float64 in index order (no BLAS, no reduction along a SIMD axis), so every
machine gets the same bits. The renderer's own cube is the batches' mean of the same
composition per batch; the two differ by float32 rounding only (about 1.7e-7 of the cube's
scale on the default room, measured by ``make bench``, storage). Every layer of the sample is
computed from this cube, so the identities hold on it as before.

``ē`` is stored in the header of the layer's file as ``spectrinsic.light_means.<layer>``
(JSON of float64 written as their shortest repr: exact), so the rebuild needs no spectra.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import DatasetError
from ...render.algebra.batch_means import batch_mean
from ...render.algebra.light_transport import light_band_means
from ...render.algebra.shares import compose
from ...render.result import RenderResult
from ...scenes.model import Scene
from ..formats.exr import read_exr_attributes, read_exr_stacks
from . import TRANSPORT_NAME
from .transport_exr import is_compact, transport_layer

if TYPE_CHECKING:
    from ...render.algebra.light_transport import LightTransport

__all__ = ["CUBE_MODE", "MEANS_ATTRIBUTE", "CubeFactors", "cube_factors", "read_cube_factors"]

#: The render mode of the cube.
CUBE_MODE = "bands31"
#: Header attribute of the file holding a ``transport_sum`` layer: its ``(L, K)`` ``ē``.
MEANS_ATTRIBUTE = "spectrinsic.light_means.{layer}"
#: Most lights a header may declare, so a damaged file cannot make the reader read without bound.
_LIGHTS_MAX = 4096


@dataclass(frozen=True, eq=False)
class CubeFactors:
    """The stored transport means ``(L, H, W, K)`` float32 and the lights' ``ē`` ``(L, K)``
    float64 the cube is composed of (module notes)."""

    means: np.ndarray
    light_means: np.ndarray

    def cube(self) -> np.ndarray:
        """``(H, W, K)`` float32 ``Σ_l T̄_l ∘ ē_l`` (module notes)."""
        return compose(self.means, self.light_means)

    def attribute(self) -> str:
        """``ē`` as the header attribute's JSON (exact)."""
        return json.dumps(self.light_means.tolist(), separators=(",", ":"), allow_nan=False)


def cube_factors(
    transport: LightTransport | None, scene: Scene, *, data_dir: str | None = None
) -> CubeFactors | None:
    """The factors of the cube of a sample written with *transport* (``None`` without a
    transport of the cube's mode)."""
    if transport is None or CUBE_MODE not in transport.modes:
        return None
    # the mean transport_exr writes (same function, same arrays: the same bits)
    means = batch_mean([b[CUBE_MODE] for b in transport.batches])
    sensors = transport.sensors[CUBE_MODE]
    return CubeFactors(means, light_band_means(scene, sensors, data_dir=data_dir))


def with_cube(result: RenderResult, factors: CubeFactors | None) -> RenderResult:
    """*result* (a :class:`~spectrinsic.render.result.RenderResult`) with its raw cube replaced
    by the one its stored transport defines (unchanged without *factors* or a cube)."""
    if factors is None or CUBE_MODE not in result.raw:
        return result
    return dataclasses.replace(result, raw={**result.raw, CUBE_MODE: factors.cube()})


def read_cube_factors(
    meta: Mapping[str, Any], path_of: Callable[[str], Path], file: str, key: str, bands: int
) -> CubeFactors:
    """The :class:`CubeFactors` of the layer *key* stored in *file* as ``transport_sum``: the
    means from ``transport.exr`` (through *path_of*), ``ē`` from *file*'s header; one-line
    :class:`DatasetError` where the sample's transport or the header do not give them."""
    record = meta.get("transport")
    lights = record.get("lights") if isinstance(record, Mapping) else None
    if (
        not isinstance(record, Mapping)
        or not is_compact(record)
        or CUBE_MODE not in (record.get("modes") or ())
        or type(lights) is not int
        or not 0 < lights <= _LIGHTS_MAX
    ):
        raise DatasetError(
            f"meta.json: layer {key!r} is stored as its transport's sum; expected a compact "
            f"transport record with the {CUBE_MODE!r} mode"
        )
    table = _light_means(path_of(file), MEANS_ATTRIBUTE.format(layer=key), (lights, bands))
    layers = [transport_layer(j, None, CUBE_MODE) for j in range(lights)]
    means = read_exr_stacks(path_of(TRANSPORT_NAME), {CUBE_MODE: layers})[CUBE_MODE]
    if means.shape[-1] != bands:
        raise DatasetError(f"{TRANSPORT_NAME}: {CUBE_MODE} means have {means.shape[-1]} bands")
    return CubeFactors(means, table)


def _light_means(path: Path, name: str, shape: tuple[int, int]) -> np.ndarray:
    """The ``(L, K)`` table of the header attribute *name* of the EXR file *path*."""
    text = str(read_exr_attributes(path).get(name))
    try:
        table = np.asarray(json.loads(text), np.float64) if len(text) < 1 << 22 else None
    except (ValueError, TypeError, RecursionError):
        table = None
    if table is None or table.shape != shape or not np.isfinite(table).all():
        raise DatasetError(
            f"EXR file {str(path)!r}: header attribute {name!r} is not a "
            f"{shape[0]} x {shape[1]} table of finite light band means"
        )
    return table
