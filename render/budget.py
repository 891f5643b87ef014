"""Memory a render needs, estimated before it starts, against the memory this machine has.

A render holds, per pixel and per colour mode, the raw K channels and their XYZ, once more per
light when each light is rendered alone, as float32; Mitsuba's film and its numpy copy hold
another two. :func:`estimate_render_bytes` counts those arrays, times
:data:`OVERHEAD_FACTOR` for the copies made on the way (measured: 780 B/pixel of peak RSS growth
for the four default modes of ``obj-apple`` between 128 x 128 and 1024 x 128, where the count
times the factor gives 684). It is an estimate of the least a render needs, so a refused size
could never have worked, and a size it lets through can still be too large for the ground truth.
"""

from __future__ import annotations

import os
from pathlib import Path

from spectrinsic.errors import RenderError
from spectrinsic.render.modes import get_mode, n_passes
from spectrinsic.render.settings import RenderSettings

__all__ = [
    "BYTES_PER_VALUE",
    "OVERHEAD_FACTOR",
    "MAX_SIDE",
    "estimate_render_bytes",
    "available_memory_bytes",
    "check_render_size",
]

#: float32.
BYTES_PER_VALUE = 4
#: Film, its numpy copy and the result's own array: three copies of every channel.
OVERHEAD_FACTOR = 3
#: Longest image side accepted at all (OpenEXR and Mitsuba films use 32-bit sizes).
MAX_SIDE = 65_536


def estimate_render_bytes(
    width: int,
    height: int,
    settings: RenderSettings,
    *,
    n_lights: int = 1,
    data_dir: str | None = None,
) -> int:
    """Least memory in bytes that rendering ``settings.modes`` at ``width x height`` takes
    (see module)."""
    values = 0
    for name in settings.modes:
        raw = 3 * n_passes(get_mode(name), data_dir=data_dir)
        values += raw + 3  # raw channels + XYZ
    per_light = settings.per_light and n_lights > 1
    copies = 1 + (n_lights if per_light else 0) + (1 if settings.direct else 0)
    return width * height * values * copies * BYTES_PER_VALUE * OVERHEAD_FACTOR


def available_memory_bytes() -> int | None:
    """Memory available to new allocations (``MemAvailable`` on Linux), or ``None`` if unknown."""
    try:
        for line in Path("/proc/meminfo").read_text(encoding="ascii").splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def check_render_size(
    width: int, height: int, settings: RenderSettings, *, what: str, processes: int = 1,
    n_lights: int = 1, data_dir: str | None = None,
) -> int:
    """Refuse a size that is not positive, too large, or cannot fit in memory; return the estimate.

    Parameters
    ----------
    what
        How the user gave the size, for the message (``"--width 100000 --height 128"``).
    processes
        Renders running at once (worker processes), each needing the estimate.
    n_lights
        Lights of the scene (each rendered alone with ``settings.per_light``).

    Raises
    ------
    RenderError
        One line naming *what*, the estimate and the memory available.
    """
    for side, value in (("width", width), ("height", height)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise RenderError(f"{what}: image {side} {value!r}; expected a positive integer")
        if value > MAX_SIDE:
            raise RenderError(f"{what}: image {side} {value} exceeds the largest supported, {MAX_SIDE}")
    need = processes * estimate_render_bytes(width, height, settings, n_lights=n_lights, data_dir=data_dir)
    have = available_memory_bytes()
    if have is not None and need > have:
        raise RenderError(
            f"{what}: rendering {width}x{height} needs at least {need / 2**30:.1f} GiB but only "
            f"{have / 2**30:.1f} GiB of memory is available; choose a smaller size"
        )
    return need
