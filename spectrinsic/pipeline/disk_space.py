"""The disk a dataset build needs, estimated from its plan before the first sample, against the
free space where ``--out`` lies.

A sample's folder holds a fixed part (``meta.json``, ``scene.json``, the PNG previews: about
:data:`SAMPLE_FIXED_BYTES`) and per pixel its compressed EXR layers. The per-pixel sizes were
measured on built samples (ZIP-compressed float EXR; a textured room compresses less than a
plain scene, so the room's figures are used):

=======================  =============  ===============================================
what                     bytes / pixel  measured
=======================  =============  ===============================================
default layers           180            11.3 MB of EXR for a 256² two-light room with the
                                        layers stored as their factors (issue 45, ``make
                                        bench`` ``storage``; 320 before)
without ``bands31``      160            the preview preset: half of the default's before
                                        issue 45 (477 kB against 943 kB for a 64² plane; not
                                        re-measured since: an upper bound)
``--store-transport``    300 per light  the compact transport (issue 45, ``make bench``
                                        ``storage``): 28.9 MB for a 256² two-light matte room
                                        (220 per light), 19.5 MB for a one-light glossy room
                                        (297, its glossy parts included)
``--spectral-layers``    210            +13.5 MB per 256² sample (``spectral.exr``, ``make
                                        bench`` ``storage``; 370 before issue 45)
``--write-cube``         124            31 float32 bands, uncompressed (an upper bound)
``--camera``             100            raw mosaic and DNG (16 bit), processed layers
=======================  =============  ===============================================

Samples are counted at the plan's ``--resolution`` (a scene file keeping its own camera size
is counted at the preset's). Each relit variant (``--relight N``) is a sample without the
transport. Lights are counted as
two (the library's two-colour conditions), as the render budget does. The dataset's own files
(manifest, card, gallery) add :data:`DATASET_FIXED_BYTES` and a gallery entry per sample. The
estimate is typical, not a bound: a build refused here would not have fitted, or nearly not;
``--ignore-disk-space`` goes ahead anyway.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from ..errors import DiskFullError
from .presets import DatasetConfig

__all__ = [
    "SAMPLE_FIXED_BYTES",
    "DATASET_FIXED_BYTES",
    "estimate_sample_bytes",
    "estimate_build_bytes",
    "check_disk_space",
]

#: ``meta.json``, ``scene.json``, previews and the gallery entry of one sample (measured
#: 60-100 kB; more previews with more cameras).
SAMPLE_FIXED_BYTES = 128 * 1024
#: Manifest, dataset card, diversity figure, gallery files (measured 280-300 kB).
DATASET_FIXED_BYTES = 1024 * 1024
#: Lights per sample assumed for the transport (the library's two-colour conditions).
_LIGHTS = 2


def estimate_sample_bytes(config: DatasetConfig) -> int:
    """Bytes one sample folder of *config* takes on disk, relit variants included (module
    table)."""
    bands31 = "bands31" in config.render.modes
    per_pixel = 180 if bands31 else 160
    per_pixel += 210 if config.spectral_layers else 0
    per_pixel += 124 if config.write_cube else 0
    per_pixel += 100 if config.camera else 0
    pixels = config.width * config.height
    sample = SAMPLE_FIXED_BYTES + pixels * per_pixel
    transport = pixels * 300 * _LIGHTS if config.store_transport else 0
    return sample * (1 + config.relight) + transport


def estimate_build_bytes(config: DatasetConfig, n_samples: int) -> int:
    """Bytes a build of *n_samples* samples of *config* writes (module notes)."""
    return DATASET_FIXED_BYTES + n_samples * estimate_sample_bytes(config)


def _free_bytes(out: Path) -> int:
    """Free bytes on the file system where *out* is (or will be made)."""
    existing = next(p for p in (out, *out.absolute().parents) if p.is_dir())
    return shutil.disk_usage(existing).free


def _size(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB"):
        if n < 1000:
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1000
    return f"{n:.1f} TB"


def check_disk_space(out: Path, config: DatasetConfig, n_samples: int) -> None:
    """Refuse a build of *n_samples* samples that cannot fit on the disk of *out*.

    Raises
    ------
    DiskFullError
        One line with the estimate, the free space and the way to go ahead anyway.
    """
    if n_samples <= 0:
        return
    need, free = estimate_build_bytes(config, n_samples), _free_bytes(out)
    if need > free:
        raise DiskFullError(
            f"--out {str(out)!r}: the build needs about {_size(need)} ({n_samples} sample(s) of "
            f"about {_size(estimate_sample_bytes(config))} at {config.width}x{config.height}, "
            f"preset {config.preset!r}) but only {_size(free)} is free there; free some space, "
            "build fewer or smaller samples, or pass --ignore-disk-space to go ahead anyway"
        )
