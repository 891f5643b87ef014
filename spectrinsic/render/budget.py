"""Memory a render needs, estimated before it starts, against the memory this machine has.

:func:`estimate_render_bytes` counts per pixel the float32 values a render holds (per mode the
raw K channels and their XYZ, once more per light when each light's share is kept, plus the
AOVs) times :data:`OVERHEAD_FACTOR` (the copies made on the way to the files); the band-path
traversal's film (:func:`traversal_channels`: one channel per light and band of every diagonal
mode for each part it accumulates, one per surface for the first-hit coverage) times
:data:`FILM_COPIES`; the float64 material and object coverage the AOVs are assembled from; and
:data:`BASE_BYTES` for the process (Python, Mitsuba, the compiled kernels). The film grows with
the lights and surfaces of a scene (800 channels for a 4-light interior of 300 meshes), so the
scene's counts (:class:`RenderLoad`) are part of the estimate; the samples per pixel are not:
Mitsuba's symbolic loops keep no per-sample state (256 x 256 peaked at 304 MiB at spp 64, and
350 x 200 the same at spp 8 and 32). The per-light terms are checked against measured peaks of
multi-light, environment-map scenes in docs/artist-interior-speed.md ("The size check's
estimate"). The estimate is an upper bound of the measured peak resident memory
(``ru_maxrss``) of ``spectrinsic render obj-apple`` with the four default modes (73 values per
pixel with the AOVs), spp 16, on the 2-core CI machine:

=========  ===========================  ==========
size       measured                     estimate
=========  ===========================  ==========
8 x 8      277 MiB (passes)             2.0 GiB
64 x 64    1215 MiB (single, full suite) 2.0 GiB
192 x 192  1215 MiB (single, full suite) 2.0 GiB
256 x 256  305 / 348 MiB (passes/single) 2.2 GiB
512 x 512  488 / 608 MiB (passes/single) 2.6 GiB
2048^2     5.0 GB (passes)              13.1 GB
=========  ===========================  ==========

(obj-apple's counts: the film term adds 51 channels. The 2048^2 row is issue 17's, rendered
with the passes, which have no traversal film, so the estimate is 2.6 x over it. The 1215 MiB
rows, the largest of four measurements inside full ``make test`` runs on a loaded machine,
1148-1215 MiB, modes spectral, rgb3, rgb6, spp 2, set :data:`BASE_BYTES`: the same render
alone peaks at 240 MiB warm and 259 MiB with an empty kernel cache, and a cold LLVM compile of
the single traversal at about 850 MiB; the cause, other work in the test process's
environment, is not isolated.) So a size refused here could not have worked, and a size let
through fits with the margin of the table.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from ..errors import RenderError
from ..scenes.model import Scene
from ..spectra import get_sensors
from .algebra.modes import get_mode, n_passes
from .base.translate import surfaces
from .settings import RenderSettings

__all__ = [
    "RenderLoad",
    "PLANNED_LOAD",
    "traversal_channels",
    "BYTES_PER_VALUE",
    "OVERHEAD_FACTOR",
    "BASE_BYTES",
    "AOV_VALUES",
    "FILM_COPIES",
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
#: Resident memory of a render process before its first pixel (the module's table), and
#: PyTorch where the torch extra is installed (pyoidn imports it: 1549 MiB at 64 x 64 then).
BASE_BYTES = 2048 * 2**20
#: AOV values per pixel: coverage of up to 9 materials, 2 ids, depth, 3 normals, the mask.
AOV_VALUES = 16
#: Longest image side accepted at all (OpenEXR and Mitsuba films use 32-bit sizes).
MAX_SIDE = 65_536
#: Copies of every channel of the band-path traversal's image alive at once: a render peaks at
#: two (the film's storage and its developed tensor, then the tensor and its numpy copy:
#: :func:`~spectrinsic.render.base.sample_split.split_render` gives each back at once; in two
#: parts, the first part's copy and the second's storage, merged a block of rows at a time) beside
#: the previous batch's cuts of it per mode, and merging the batches holds both batches' cuts
#: and their mean: three. Was 4 (3.9 to 4.4 measured inside the render call, before the copies
#: were released); measured peaks against it: docs/artist-interior-speed.md.
FILM_COPIES = 3


@dataclass(frozen=True)
class RenderLoad:
    """What of a scene sizes its render's memory besides the image size and the modes.

    Attributes
    ----------
    n_lights
        Lights L (each light's share is a set of accumulators of the band path).
    n_surfaces
        BSDF-carrying shapes S (:func:`~spectrinsic.render.base.translate.surfaces`): one
        first-hit coverage channel each.
    n_texcols
        Texture columns T (basis materials of the textured meshes,
        :func:`~spectrinsic.render.base.textures.texture_tables`): one channel each.
    n_materials
        Materials M (a float64 coverage map each while the AOVs are assembled).
    n_objects
        Distinct object ids O (a float64 coverage map each, likewise).
    glossy
        Whether a material has a non-diffuse lobe (the specular accumulators).
    metals
        Whether a material has no diffuse lobe (metal, mirror, glass: the white-at-metal ones).
    """

    n_lights: int = 1
    n_surfaces: int = 0
    n_texcols: int = 0
    n_materials: int = 0
    n_objects: int = 0
    glossy: bool = False
    metals: bool = False

    @classmethod
    def of_scene(cls, scene: Scene) -> RenderLoad:
        """The counts of *scene*."""
        textured = [m.texture for m in scene.meshes if m.texture is not None]
        return cls(
            n_lights=len(scene.lights),
            n_surfaces=len(surfaces(scene)),
            n_texcols=len({b for t in textured for b in t.basis}),  # texture_tables' columns
            n_materials=len(scene.materials),
            n_objects=len({m.object_id for m in scene.meshes}),
            glossy=any(m.glossy for m in scene.materials),
            metals=any(m.non_diffuse for m in scene.materials),
        )


#: Counts the render-size check sizes a library or generated dataset by, whose scenes do not
#: exist before the build (a ``--scenes`` one is sized by each file's own): the largest of the
#: library (2 lights, 25 surfaces, 23 materials, 14 objects, glossy and metal variants;
#: tests/render/test_planned_load.py checks every scene) and of 24 generated scenes (4 lights,
#: 103 surfaces, 98 materials, 19 objects, no texture), rounded up. A planning figure for
#: generated scenes (their counts are drawn), not a bound proven for every draw.
PLANNED_LOAD = RenderLoad(
    n_lights=4,
    n_surfaces=112,
    n_texcols=8,
    n_materials=104,
    n_objects=24,
    glossy=True,
    metals=True,
)


def traversal_channels(
    settings: RenderSettings, load: RenderLoad, *, data_dir: str | None = None
) -> tuple[int, int]:
    """Channels per pixel of the image the band-path traversal's ``mi.render`` returns
    (:mod:`~spectrinsic.render.band_path`): the first traversal's and, with
    ``settings.direct``, the direct-light one's (else 0).

    The image holds R, G, B (Mitsuba's ``hdrfilm``; its image block one more, the weight), then
    the AOVs of :func:`~spectrinsic.render.band_path.integrator.aov_channels`: one accumulator
    per light and band of every diagonal mode (K = Σ bands), L·K each for the transport, the
    specular part (glossy scenes) and the white-at-metal part (first traversal, scenes with
    metals), and with ``settings.aovs`` the first-hit maps: S coverages, T texture columns,
    the ray distance and the normal."""
    k = sum(
        get_sensors(mode.sensors, data_dir=data_dir).n
        for mode in (get_mode(name) for name in settings.modes)
        if mode.kind == "diagonal"
    )
    if k == 0 and not settings.aovs:
        return 0, 0
    k = k or 3  # the first-hit maps alone come from an rgb3 traversal (render_jobs)
    lk = load.n_lights * k
    maps = load.n_surfaces + load.n_texcols + 4 if settings.aovs else 0
    first = 3 + lk * (1 + load.glossy + load.metals) + maps
    direct = 3 + lk * (1 + load.glossy) if settings.direct and k else 0
    return first, direct


def estimate_render_bytes(
    width: int,
    height: int,
    settings: RenderSettings,
    *,
    load: RenderLoad = RenderLoad(),
    data_dir: str | None = None,
) -> int:
    """Upper bound of the peak memory in bytes of rendering ``settings.modes`` at
    ``width x height`` in one process (see the module's table): the result's values and the
    band-path traversal's film (:func:`traversal_channels`) per pixel, and the process."""
    values = 0
    for name in settings.modes:
        raw = 3 * n_passes(get_mode(name), data_dir=data_dir)
        values += raw + 3  # raw channels + XYZ
    # each light's share is held even for one light (scene_render: one share per main job)
    copies = 1 + (load.n_lights if settings.per_light else 0) + (1 if settings.direct else 0)
    result = (values * copies + AOV_VALUES) * BYTES_PER_VALUE * OVERHEAD_FACTOR
    first, direct = traversal_channels(settings, load, data_dir=data_dir)
    film = (first + direct) * FILM_COPIES * BYTES_PER_VALUE
    # the AOVs' per-material and per-object coverage maps (float64) are assembled from the film
    maps = (load.n_materials + load.n_objects) * 8 if settings.aovs else 0
    return BASE_BYTES + width * height * (result + film + maps)


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
    load: RenderLoad = RenderLoad(),
    data_dir: str | None = None,
) -> int:
    """Refuse a size that is not positive, too large, or cannot fit in memory; return the estimate.

    Parameters
    ----------
    what
        How the user gave the size, for the message (``"--width 100000 --height 128"``).
    processes
        Renders running at once (worker processes), each needing the estimate.

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
    need = processes * estimate_render_bytes(width, height, settings, load=load, data_dir=data_dir)
    have = available_memory_bytes()
    if have is not None and need > have:
        raise RenderError(
            f"{what}: rendering {width}x{height} needs at least {need / 2**30:.1f} GiB but only "
            f"{have / 2**30:.1f} GiB of memory is available; choose a smaller size"
        )
    return need
