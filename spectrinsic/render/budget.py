"""Memory a render needs, estimated before it starts, against the memory this machine has.

A render holds, per pixel and per colour mode, the raw K channels and their XYZ, once more per
light when each light is rendered alone, plus the AOVs (coverage, ids, depth, normals), as
float32. :func:`estimate_render_bytes` counts those values, times :data:`OVERHEAD_FACTOR` for
the copies made on the way (film, numpy copies, EXR encoding), plus :data:`BASE_BYTES` for the
process itself (Python, Mitsuba, the compiled kernels). It is calibrated to be an upper bound
of the measured peak resident memory (``ru_maxrss``) of ``spectrinsic render obj-apple`` with
the four default modes (73 values per pixel with the AOVs), spp 16, on the 2-core CI machine:

=========  ===========================  ==========
size       measured                     estimate
=========  ===========================  ==========
8 x 8      277 MiB (passes)             1.0 GiB
64 x 64    1215 MiB (single, full suite) 1.6 GiB
192 x 192  1215 MiB (single, full suite) 1.6 GiB
256 x 256  305 / 348 MiB (passes/single) 1.6 GiB
512 x 512  488 / 608 MiB (passes/single) 1.9 GiB
2048^2     5.0 GB (passes)              8.9 GB
=========  ===========================  ==========

(the 2048^2 figure from issue 17, where the former count, 684 B/pixel without the process,
estimated 1.7 GiB). The 1215 MiB rows are the largest of four measurements made inside
full ``make test`` runs on a loaded machine (1148-1215 MiB, modes spectral, rgb3, rgb6, spp 2;
the same render alone peaks at 240 MiB warm and 259 MiB with an empty kernel cache; the
cause, other work in the test process's environment, is not isolated); they set
:data:`BASE_BYTES`. Earlier: the single traversal (``RenderSettings.integrator="single"``) compiles one
large kernel: a cold LLVM compile (a mode set not yet in Dr.Jit's kernel cache) peaks at about
850 MiB whatever the size, which sets :data:`BASE_BYTES`. The samples per pixel do not matter:
256 x 256 at spp 64 peaked at 304 MiB, as Mitsuba's symbolic loops keep no per-sample state. So
a size refused here could not have worked, and a size let through fits with the margin of the
table.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import RenderError
from .algebra.modes import get_mode, n_passes
from .settings import RenderSettings

__all__ = [
    "BYTES_PER_VALUE",
    "OVERHEAD_FACTOR",
    "BASE_BYTES",
    "AOV_VALUES",
    "MAX_SIDE",
    "estimate_render_bytes",
    "available_memory_bytes",
    "check_render_size",
]

#: float32.
BYTES_PER_VALUE = 4
#: Copies of every value on the way to the files: the film, its numpy copies, the result's
#: arrays, the EXR encoder's buffers (fitted: 1120 B/pixel measured at 2048^2 for 73 values is
#: 3.8 copies; 6 keeps the estimate above every measurement of the module's table).
OVERHEAD_FACTOR = 6
#: Resident memory of a render process before its first pixel, a cold compile of the single
#: traversal's kernel included (up to 1215 MiB measured at 64 x 64 and 192 x 192 inside full
#: test runs; 277 MiB at 8 x 8 with the passes), and PyTorch where the torch extra is
#: installed (pyoidn imports it: 1549 MiB at 64 x 64 then); the margin covers other builds.
BASE_BYTES = 2048 * 2**20
#: AOV values per pixel: coverage of up to 9 materials, 2 ids, depth, 3 normals, the mask.
AOV_VALUES = 16
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
    """Upper bound of the peak memory in bytes of rendering ``settings.modes`` at
    ``width x height`` in one process (see the module's table)."""
    values = 0
    for name in settings.modes:
        raw = 3 * n_passes(get_mode(name), data_dir=data_dir)
        values += raw + 3  # raw channels + XYZ
    per_light = settings.per_light and n_lights > 1
    copies = 1 + (n_lights if per_light else 0) + (1 if settings.direct else 0)
    per_pixel = (values * copies + AOV_VALUES) * BYTES_PER_VALUE * OVERHEAD_FACTOR
    return BASE_BYTES + width * height * per_pixel


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
    width: int,
    height: int,
    settings: RenderSettings,
    *,
    what: str,
    processes: int = 1,
    n_lights: int = 1,
    data_dir: str | None = None,
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
            raise RenderError(
                f"{what}: image {side} {value} exceeds the largest supported, {MAX_SIDE}"
            )
    need = processes * estimate_render_bytes(
        width, height, settings, n_lights=n_lights, data_dir=data_dir
    )
    have = available_memory_bytes()
    if have is not None and need > have:
        raise RenderError(
            f"{what}: rendering {width}x{height} needs at least {need / 2**30:.1f} GiB but only "
            f"{have / 2**30:.1f} GiB of memory is available; choose a smaller size"
        )
    return need
