"""spectrinsic.render: Mitsuba 3 backends (the only package importing ``mitsuba``/``drjit``).

Nothing is imported from Mitsuba when this package is imported; variants are chosen per pass
(:mod:`~spectrinsic.render.base.variants`) and set only inside ``variant_scope`` blocks. The
code map is docs/ARCHITECTURE.md; this face holds what the CLI, the pipeline, the benches and
the tests call (other names are imported from their modules):

- :func:`render_scene` (:class:`RenderSettings`, a seed) -> :class:`RenderResult`: every mode
  of one scene as CIE XYZ; :func:`render_batches` renders it as independent batches whose
  spread measures the Monte Carlo noise, and :func:`count_passes` counts its Mitsuba passes.
- :func:`render_diagonal`, :func:`render_aovs`: the passes (the converged-reference route).
- :func:`get_mode`, :func:`channel_values`, :func:`to_xyz_matrix`: the modes and Eq. 5.2.
- :func:`scene_to_mitsuba`: the one translation of a scene into a Mitsuba dict.
"""

from .algebra.batch_means import image_noise, merge_batches
from .algebra.modes import channel_values, get_mode, to_xyz_matrix
from .base.translate import scene_to_mitsuba
from .base.variants import choose_variant, set_thread_count, variant_scope
from .batches import render_batches
from .passes import render_diagonal
from .passes.aovs import render_aovs
from .result import RenderResult
from .scene_render import count_passes, render_scene
from .settings import RenderSettings

__all__ = [
    "RenderResult",
    "RenderSettings",
    "channel_values",
    "choose_variant",
    "count_passes",
    "get_mode",
    "image_noise",
    "merge_batches",
    "render_aovs",
    "render_batches",
    "render_diagonal",
    "render_scene",
    "scene_to_mitsuba",
    "set_thread_count",
    "to_xyz_matrix",
    "variant_scope",
]
