"""OpenEXR files with named layers and channels: float32 data, int32 ids.

A *layer* is a named array: ``(H, W)`` for one channel, ``(H, W, C)`` for several. It is stored
as EXR channels ``<layer>.<channel>`` (``reflectance.R``, ``depth.Z``, ``cube.b05``), as 32-bit
float (ground truth is never written as half floats; only a noise estimate that is part of no
identity may be, when its writer names it in ``half``), or, for integer layers (material and
object ids), as 32-bit UINT channels holding the int32 bits, so every id up to 2**31 - 1 reads
back exactly (float32 stops at 2**24: id 16777217 came back 16777216). The channel order of
every layer is kept in a header attribute so that reading gives back the arrays bit for bit.

This is the only module of spectrinsic that imports ``OpenEXR``.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import sys
import tempfile
import threading
from collections.abc import Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...file_writes import replacing
from ...threads import array_threads, thread_map

__all__ = [
    "write_exr",
    "read_exr",
    "read_exr_stacks",
    "read_exr_attributes",
    "exr_size",
    "default_channel_names",
]

#: The lossless EXR compressions :func:`write_exr` offers, by name (the OpenEXR constant).
COMPRESSIONS = {
    "zip": "ZIP_COMPRESSION",
    "zips": "ZIPS_COMPRESSION",
    "piz": "PIZ_COMPRESSION",
    "none": "NO_COMPRESSION",
}
#: The compression of every EXR file but the transport's (lossless zlib, 16 scanlines a block).
DEFAULT_COMPRESSION = "zip"

log = logging.getLogger(__name__)
#: Serialises :func:`_c_output_held` (file descriptors are shared by all threads).
_HOLD = threading.RLock()

#: Header attribute holding ``{layer: [channel, ...]}`` as JSON.
CHANNELS_ATTRIBUTE = "spectrinsic.channels"
#: Header attribute listing the layers whose UINT channels hold the bits of int32 values (ids,
#: -1 = 4294967295 for background), so they read back as int32.
INT32_ATTRIBUTE = "spectrinsic.int32"
_INT32 = np.iinfo(np.int32)


def default_channel_names(n_channels: int) -> tuple[str, ...]:
    """Channel names used when none are given: ``Y`` for 1, ``R, G, B`` for 3, else ``c00, ...``."""
    if n_channels == 1:
        return ("Y",)
    if n_channels == 3:
        return ("R", "G", "B")
    return tuple(f"c{i:02d}" for i in range(n_channels))


def _as_int32_bits(name: str, array: np.ndarray) -> np.ndarray:
    """An integer array as the uint32 bits of its int32 values (range-checked: exact or refused)."""
    if array.size and (array.min() < _INT32.min or array.max() > _INT32.max):
        raise DatasetError(
            f"layer {name!r} holds integers beyond the 32-bit range "
            f"[{_INT32.min}, {_INT32.max}]; ids are stored as int32"
        )
    return array.astype(np.int32).view(np.uint32)


def _as_stored(name: str, array: np.ndarray, half: bool = False) -> np.ndarray:
    """*array* as it is stored: integers as int32 bits (uint32), a *half* layer as float16
    (finite values only), everything else as float32."""
    array = np.asarray(array)
    if half:
        if array.dtype != np.float16 or not np.isfinite(array).all():
            raise DatasetError(f"layer {name!r}: a half layer must be finite float16")
        return array
    if array.dtype == np.float16:
        raise DatasetError(f"layer {name!r} is float16; ground truth is stored as float32 only")
    if array.dtype.kind in "iu":
        return _as_int32_bits(name, array)
    if array.dtype.kind not in "fb":
        raise DatasetError(f"layer {name!r} has dtype {array.dtype}; expected a numeric array")
    if array.dtype == np.float64:
        finite = np.isfinite(array)
        big = np.abs(array[finite]) > np.finfo(np.float32).max
        if big.any():
            raise DatasetError(f"layer {name!r} has values beyond the float32 range")
    return array.astype(np.float32, copy=False)


def _channels(
    layers: Mapping[str, np.ndarray],
    channel_names: Mapping[str, Sequence[str]],
    half: Collection[str],
) -> tuple[dict[str, np.ndarray], dict[str, list[str]]]:
    """The EXR channels ``<layer>.<channel>`` of *layers* as stored (:func:`_as_stored`), and
    each layer's channel order; one-line errors for names, shapes and sizes that do not fit."""
    channels: dict[str, np.ndarray] = {}
    order: dict[str, list[str]] = {}
    shape: tuple[int, int] | None = None
    for name, array in layers.items():
        if "." in name:
            raise DatasetError(f"layer name {name!r} contains '.'; expected a plain name")
        data = _as_stored(name, array, name in half)
        if data.ndim == 2:
            data = data[..., None]
        if data.ndim != 3:
            raise DatasetError(
                f"layer {name!r} has shape {data.shape}; expected (H, W) or (H, W, C)"
            )
        if shape is None:
            shape = (int(data.shape[0]), int(data.shape[1]))
        elif data.shape[:2] != shape:
            raise DatasetError(
                f"layer {name!r} has size {data.shape[:2]}; expected {shape} like the other layers"
            )
        names = tuple(channel_names.get(name, default_channel_names(data.shape[2])))
        if len(names) != data.shape[2] or len(set(names)) != len(names):
            raise DatasetError(
                f"layer {name!r} has {data.shape[2]} channels but channel names {names!r}"
            )
        order[name] = list(names)
        for i, channel in enumerate(names):
            # The bindings read the buffer as C-contiguous regardless of strides: a channel
            # slice a[..., i] written directly comes back scrambled.
            channels[f"{name}.{channel}"] = np.ascontiguousarray(data[..., i])
    return channels, order


def write_exr(
    path: str | os.PathLike[str],
    layers: Mapping[str, np.ndarray],
    *,
    channel_names: Mapping[str, Sequence[str]] | None = None,
    attributes: Mapping[str, str] | None = None,
    compression: str = DEFAULT_COMPRESSION,
    half: Collection[str] = (),
) -> Path:
    """Write *layers* as float32 channels ``<layer>.<channel>`` of one scanline EXR file.

    Parameters
    ----------
    path
        Destination ``.exr`` file.
    layers
        ``{name: array}`` with arrays ``(H, W)`` or ``(H, W, C)``, all of the same ``H, W``.
        Floats and bools are stored as float32 (float16 is refused); integer arrays (ids) as
        UINT channels holding their int32 bits (values outside int32 are refused), listed in
        the header attribute :data:`INT32_ATTRIBUTE`, so they read back as exact int32.
    channel_names
        Channel names per layer, e.g. ``{"normals": ("X", "Y", "Z")}``; default
        :func:`default_channel_names`.
    attributes
        Extra string header attributes (provenance).
    compression
        One of :data:`COMPRESSIONS`, all lossless: ``"zip"`` (zlib over blocks of 16 scanlines,
        the default), ``"zips"`` (zlib per scanline: as small on Monte Carlo noise, and 4x
        faster to read back than ``"zip"`` on a 256² room's transport, 0.09 s against 0.35 s,
        which is why the transport uses it), ``"piz"`` (wavelet and Huffman coding, lossless:
        14 % smaller than ZIP on the float32 band images of a 256² room, read as fast, larger
        on piecewise-constant layers; :mod:`~spectrinsic.gt_export.sample.stored_layers`
        chooses it per file) or ``"none"``.
    half
        Layers given as float16 arrays and stored as HALF channels: only estimates that are
        part of no identity (the transport's batch deviations, which feed the noise layer).

    Returns
    -------
    Path
        *path*.
    """
    import OpenEXR

    channels, order = _channels(layers, dict(channel_names or {}), half)
    if not channels:
        raise DatasetError(f"no layers to write to {str(path)!r}")
    if compression not in COMPRESSIONS:
        raise DatasetError(f"EXR compression {compression!r}; expected one of {list(COMPRESSIONS)}")
    header = {
        "compression": getattr(OpenEXR, COMPRESSIONS[compression]),
        "type": OpenEXR.scanlineimage,
        CHANNELS_ATTRIBUTE: json.dumps(order, separators=(",", ":"), allow_nan=False),
    }
    int32 = [name for name, array in layers.items() if np.asarray(array).dtype.kind in "iu"]
    if int32:  # only then: a file without ids keeps its header (and its bytes) as before
        header[INT32_ATTRIBUTE] = json.dumps(int32, separators=(",", ":"), allow_nan=False)
    for key, value in (attributes or {}).items():
        header[str(key)] = str(value)
    path = Path(path)
    with replacing(path) as tmp:
        OpenEXR.File(header, channels).write(str(tmp))
    return path


@contextlib.contextmanager
def _c_output_held() -> Iterator[None]:
    """Hold what is written to file descriptors 1 and 2 during the block: OpenEXR prints its
    own lines about a damaged file there (its C core to stderr, the bindings' "Warning: ..." to
    stdout) before it fails. Given back after a block that ends normally; dropped (logged at
    debug level) after one that raises, whose error is then the one line the user sees."""
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    with _HOLD, tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        saved = {fd: os.dup(fd) for fd in (1, 2)}  # one thread at a time: they are the process's
        held = {1: out, 2: err}
        for fd, file in held.items():
            os.dup2(file.fileno(), fd)
        failed = True
        try:
            yield
            failed = False
        finally:
            for stream in (sys.stdout, sys.stderr):
                stream.flush()
            for fd, file in held.items():
                os.dup2(saved[fd], fd)
                os.close(saved[fd])
                file.seek(0)
                text = file.read()
                if text and not failed:
                    os.write(fd, text)
                elif text:
                    log.debug("OpenEXR: %s", text.decode("utf-8", "replace").strip())


def _open(path: Path, *, header_only: bool):  # noqa: ANN202 - OpenEXR.File
    import OpenEXR

    if not path.is_file():
        raise DatasetError(f"EXR file {str(path)!r} does not exist")
    try:
        with _c_output_held():
            return OpenEXR.File(str(path), separate_channels=True, header_only=header_only)
    except Exception as exc:  # the bindings raise bare RuntimeError/Exception on corrupt files
        raise DatasetError(f"EXR file {str(path)!r} cannot be read: {exc}") from exc


def _channel_order(path: Path, text: object) -> dict[str, list[str]]:
    """The :data:`CHANNELS_ATTRIBUTE` of *path*'s header: ``{layer: [channel, ...]}``."""
    try:
        order = json.loads(str(text))
    except (ValueError, RecursionError):
        order = None
    if not (
        isinstance(order, dict)
        and all(isinstance(v, list) and all(isinstance(c, str) for c in v) for v in order.values())
    ):
        raise DatasetError(
            f"EXR file {str(path)!r}: header attribute {CHANNELS_ATTRIBUTE!r} is not "
            "a JSON object of layer -> channel names"
        )
    return order


def exr_size(path: str | os.PathLike[str]) -> tuple[int, int, int]:
    """``(height, width, channels)`` of an EXR file from its header alone, so a size can be
    refused before any pixel is decoded (a small file may declare a huge image)."""
    header = read_exr_attributes(path)
    try:
        lo, hi = np.asarray(header["dataWindow"], dtype=np.int64)  # ((xMin, yMin), (xMax, yMax))
        channels: Any = header["channels"]
        return int(hi[1] - lo[1]) + 1, int(hi[0] - lo[0]) + 1, len(channels)
    except (KeyError, TypeError, ValueError) as exc:
        raise DatasetError(f"EXR file {str(path)!r} has no readable dataWindow") from exc


def read_exr_attributes(path: str | os.PathLike[str]) -> dict[str, object]:
    """Return the header of an EXR file (attributes only, no pixels)."""
    try:
        return dict(_open(Path(path), header_only=True).header())
    except Exception as exc:
        if isinstance(exc, DatasetError):
            raise
        raise DatasetError(f"EXR file {str(path)!r} has no readable header: {exc}") from exc


def _as_read(pixels: np.ndarray, int32: bool) -> np.ndarray:
    """Stored pixels as returned: int32 ids from their UINT bits, everything else as float32."""
    if int32:
        return np.asarray(pixels, dtype=np.uint32).view(np.int32)
    return np.asarray(pixels, dtype=np.float32)


@dataclass(frozen=True, eq=False)
class _Decoded:
    """The channels of one decoded EXR file and how they group into layers."""

    path: Path
    pixels: dict[str, np.ndarray]
    order: dict[str, list[str]]
    int32: frozenset[str]

    def keys(self, layer: str) -> list[str]:
        """The EXR channel names of *layer*, in its channel order (one-line error if absent)."""
        if layer not in self.order:
            raise DatasetError(
                f"EXR file {str(self.path)!r} has no layer {layer!r}; it holds {sorted(self.order)}"
            )
        names = self.order[layer]
        keys = [f"{layer}.{c}" if layer else c for c in names]
        missing = [k for k in keys if k not in self.pixels]
        if missing:
            raise DatasetError(
                f"EXR file {str(self.path)!r} lacks channels {missing} of layer {layer!r}"
            )
        return keys

    def layer(self, layer: str) -> np.ndarray:
        """``(H, W)`` or ``(H, W, C)`` array of *layer* as :func:`read_exr` returns it."""
        arrays = [_as_read(self.pixels[k], layer in self.int32) for k in self.keys(layer)]
        return arrays[0] if len(arrays) == 1 else np.stack(arrays, axis=-1)


def _decode(path: Path, threads: int = 0) -> _Decoded:
    """Decode every channel of *path*, with *threads* OpenEXR threads (0: in this thread)."""
    import OpenEXR

    before = OpenEXR.global_thread_count()
    OpenEXR.set_global_thread_count(threads)
    try:
        # a corrupt chunk makes the bindings warn (held: dropped if decoding then fails) and
        # return a file with no parts, not raise
        with _c_output_held():
            exr = _open(path, header_only=False)
            try:
                header = exr.header()
                pixels = {name: ch.pixels for name, ch in exr.channels().items()}
            except Exception as exc:
                raise DatasetError(f"EXR file {str(path)!r} cannot be decoded: {exc}") from exc
    finally:
        OpenEXR.set_global_thread_count(before)
    order: dict[str, list[str]]
    if CHANNELS_ATTRIBUTE in header:
        order = _channel_order(path, header[CHANNELS_ATTRIBUTE])
    else:
        order = {}
        for full in pixels:
            layer, _, channel = full.rpartition(".")
            order.setdefault(layer, []).append(channel)
        for names in order.values():
            for canonical in (["R", "G", "B"], ["X", "Y", "Z"]):
                if sorted(names) == sorted(canonical):
                    names[:] = canonical
                    break
            else:
                names.sort()
    int32 = (
        frozenset(json.loads(header[INT32_ATTRIBUTE])) if INT32_ATTRIBUTE in header else frozenset()
    )
    return _Decoded(path, pixels, order, int32)


def read_exr(
    path: str | os.PathLike[str], *, layers: Sequence[str] | None = None
) -> dict[str, np.ndarray]:
    """Read an EXR file written by :func:`write_exr` back into ``{layer: array}``.

    Parameters
    ----------
    path
        The ``.exr`` file.
    layers
        Only these layers (default: all).

    Returns
    -------
    dict
        ``(H, W)`` float32 arrays for one-channel layers and ``(H, W, C)`` float32 arrays in the
        written channel order otherwise; integer layers (:data:`INT32_ATTRIBUTE`) as int32. Files
        from other writers are grouped by the prefix before the last ``.``, channels R, G, B /
        X, Y, Z in that order, others sorted.
    """
    decoded = _decode(Path(path))
    wanted = list(decoded.order) if layers is None else list(layers)
    return {layer: decoded.layer(layer) for layer in wanted}


def read_exr_stacks(
    path: str | os.PathLike[str], stacks: Mapping[str, Sequence[str]]
) -> dict[str, np.ndarray]:
    """Read float layers of an EXR file written by :func:`write_exr` stacked into one array per
    stack: ``{name: (N, H, W, C) float32}`` of the N layers *stacks* ``[name]`` names (each with C
    channels, in their written order), filled channel by channel from the decoded file with no
    intermediate copy (a relighting reads ~50 MB of transport this way)."""
    path = Path(path)
    decoded = _decode(path, threads=array_threads())
    missing = [layer for names in stacks.values() for layer in names if layer not in decoded.order]
    if missing:
        raise DatasetError(f"EXR file {str(path)!r} lacks the layers {missing[:3]}")
    return dict(zip(stacks, thread_map(lambda layers: _stack(decoded, layers), stacks.values())))


def _stack(decoded: _Decoded, layers: Sequence[str]) -> np.ndarray:
    """``(N, H, W, C)`` float32 of the N float *layers* of *decoded*, filled plane by plane."""
    keys = [decoded.keys(layer) for layer in layers]
    if len({len(k) for k in keys}) != 1 or decoded.int32 & set(layers):
        raise DatasetError(
            f"EXR file {str(decoded.path)!r}: layers {list(layers)[:3]} are not float layers "
            "with one channel count"
        )
    shape = decoded.pixels[keys[0][0]].shape
    stack = np.empty((len(keys), *shape, len(keys[0])), np.float32)
    for i, layer_keys in enumerate(keys):
        for c, key in enumerate(layer_keys):
            if decoded.pixels[key].shape != shape:
                raise DatasetError(
                    f"EXR file {str(decoded.path)!r}: channel {key!r} is not {shape}"
                )
            stack[i, ..., c] = decoded.pixels[key]
    return stack
