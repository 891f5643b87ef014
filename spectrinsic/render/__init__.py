"""spectrinsic.render: Mitsuba 3 backends (the only package importing ``mitsuba``/``drjit``).

Nothing is imported from Mitsuba when this package is imported; variants are chosen per pass
(:mod:`~spectrinsic.render.base.variants`) and set only inside ``variant_scope`` blocks.

- :func:`render_scene` (:class:`RenderSettings`, a seed) -> :class:`RenderResult`: the
  spectral reference and K-channel diagonal renders (``rgb3``, ``rgb6``, ``bands31``) of one scene, all as CIE XYZ, with per-light and
  direct-only renders and coverage/id/depth/normal maps; :func:`render_batches` renders it as
  independent batches whose spread measures the Monte Carlo noise.
- :mod:`~spectrinsic.render.algebra.modes`: the mode registry and the colour maths of Eq. 5.2.
- :mod:`~spectrinsic.render.passes`: the passes themselves, for any sensor set.
- :mod:`~spectrinsic.render.transport_render`: each light's band transport (:func:`render_transport`)
  and renders under any light spectra composed from it, for exact relighting.
- :mod:`~spectrinsic.render.band_path.traversal` and :mod:`~spectrinsic.render.band_path.integrator`: every diagonal
  mode, band and light in one path traversal (``RenderSettings(integrator="single")``, the
  default), with the per-light band transport (``RenderResult.transport``).
- :func:`scene_to_mitsuba`: the one translation of a scene into a Mitsuba dict.
"""

from .algebra.batch_means import batch_seeds, image_noise, merge_batches, relative_standard_error
from .algebra.light_transport import LightTransport
from .algebra.modes import (
    RENDER_MODES,
    RenderMode,
    channel_values,
    get_mode,
    to_xyz_matrix,
)
from .base.translate import scene_to_mitsuba
from .base.variants import (
    available_variants,
    choose_variant,
    llvm_library,
    set_thread_count,
    variant_report,
    variant_scope,
)
from .batches import render_batches
from .passes import render_diagonal
from .passes.aovs import render_aovs
from .result import RenderResult
from .scene_render import count_passes, render_scene
from .settings import DEFAULT_MODES, RenderSettings
from .spectral import render_spectral
from .transport_render import render_transport, render_transport_batches

__all__ = [
    "DEFAULT_MODES",
    "LightTransport",
    "RENDER_MODES",
    "RenderMode",
    "RenderResult",
    "RenderSettings",
    "available_variants",
    "batch_seeds",
    "channel_values",
    "choose_variant",
    "count_passes",
    "get_mode",
    "image_noise",
    "llvm_library",
    "merge_batches",
    "relative_standard_error",
    "render_aovs",
    "render_batches",
    "render_diagonal",
    "render_scene",
    "render_spectral",
    "render_transport",
    "render_transport_batches",
    "scene_to_mitsuba",
    "set_thread_count",
    "to_xyz_matrix",
    "variant_report",
    "variant_scope",
]
