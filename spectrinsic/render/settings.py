"""``RenderSettings``: how one scene is rendered, as one frozen record.

:func:`~spectrinsic.render.render_scene` and :func:`~spectrinsic.render.render_batches` take
this record instead of a dozen keyword arguments; the dataset config embeds it
(:class:`spectrinsic.pipeline.presets.DatasetConfig`), and the CLI, the bench and the rendering
study build it. What differs per call (the sampler seed, a progress callback, the data
directory) stays outside: the same settings render every sample of a dataset.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, NoReturn

from ..errors import RenderError

if TYPE_CHECKING:
    from .base.geometry import SurfaceGeometry
    from .base.one_pass import PassProgress

__all__ = [
    "DEFAULT_INTEGRATOR",
    "DEFAULT_MODES",
    "INTEGRATORS",
    "UINT32_MAX",
    "PassRequest",
    "RenderSettings",
]

#: Every colour mode: the spectral Monte Carlo reference and the 3-, 6- and 31-channel
#: diagonal renders (:data:`spectrinsic.render.algebra.modes.RENDER_MODES`).
DEFAULT_MODES: tuple[str, ...] = ("spectral", "rgb3", "rgb6", "bands31")
#: How the diagonal modes are rendered: ``"passes"``, ⌈K/3⌉ RGB passes per mode and one scene
#: per light (:mod:`spectrinsic.render.passes`); ``"single"``, every diagonal mode, band and
#: light from one path traversal (:mod:`spectrinsic.render.band_path.traversal`).
INTEGRATORS: tuple[str, ...] = ("passes", "single")
#: The traversal: the same images to float rounding, per-light images that are exact shares
#: of the full render, fewer Mitsuba passes.
DEFAULT_INTEGRATOR = "single"


#: Mitsuba's sampler seed and sample count are 32-bit unsigned.
UINT32_MAX = 2**32 - 1


def _refuse(name: str, value: Any, expected: str) -> NoReturn:
    """The one form of a refused render setting."""
    raise RenderError(f"render setting {name}={value!r}; expected {expected}")


def _positive(name: str, value: Any) -> None:
    """The one "at least 1" check of a count (samples, depth, batches)."""
    if not isinstance(value, int) or isinstance(value, bool) or value < 1:
        _refuse(name, value, "a positive integer")


@dataclass(frozen=True)
class RenderSettings:
    """Settings of the passes of one scene.

    Attributes
    ----------
    spp
        Samples per pixel in total, over all *batches*; every pass of one batch renders
        :attr:`batch_spp` = ``spp / batches``.
    modes
        Render modes, names of :data:`spectrinsic.render.algebra.modes.RENDER_MODES` (checked by the
        renderer against that registry).
    max_depth
        Longest path (Mitsuba convention: 2 = direct light only).
    variant
        Backend (``"cuda"``, ``"llvm"``, ``"scalar"``) or variant name; ``None``: the best usable.
    per_light
        Also render each light alone (one scene per light): the per-light images sum exactly
        to the full image.
    share_mode
        With *per_light*: render only this mode light by light (for light shares; a 1-pass mode
        such as ``"rgb3"`` costs one pass per light) and every mode once with all lights on;
        ``None``: every mode light by light.
    direct
        ``True`` for a direct-only render of every mode, or the modes that need one (e.g. only
        the reference, for r of Eq. 5.8).
    aovs
        Also compute coverage, ids, depth and normals.
    batches
        Independent batches of :attr:`batch_spp` samples, each with its own seed; two or more
        measure the Monte Carlo noise (:func:`spectrinsic.render.render_batches`).
    noise_target
        Adaptive sampling: add batches while the median relative standard error of the image
        is above this fraction (e.g. 0.02), up to *max_batches*.
    max_batches
        Cap of the adaptive batches (``None``: ``4 * batches``).
    integrator
        One of :data:`INTEGRATORS`, resolved per variant by
        :func:`spectrinsic.render.band_path.traversal.resolve_integrator`. Not hashed by a
        dataset config: both give the same pixels to float rounding.
    spectral_spp
        Samples per pixel of the spectral Monte Carlo pass over all batches (``None``: *spp*).
        The reference image, the ground truth and the per-light transport come from the
        diagonal modes; the spectral image only measures their spectral error, so a preset
        may spend fewer samples on it than on the traversal.

    >>> s = RenderSettings(8, modes=("rgb3",), batches=2)
    >>> s.batch_spp, s.with_options(spp=16).batch_spp, s.with_options(spectral_spp=2).spectral_batch_spp
    (4, 8, 1)
    >>> RenderSettings(spp=3, batches=2)
    Traceback (most recent call last):
    ...
    spectrinsic.errors.RenderError: render setting spp=3 with batches=2; expected spp divisible by batches (each batch renders spp / batches samples)
    """

    spp: int
    modes: tuple[str, ...] = DEFAULT_MODES
    max_depth: int = 8
    variant: str | None = None
    per_light: bool = False
    share_mode: str | None = None
    direct: bool | tuple[str, ...] = False
    aovs: bool = True
    batches: int = 1
    noise_target: float | None = None
    max_batches: int | None = None
    integrator: str = DEFAULT_INTEGRATOR
    spectral_spp: int | None = None

    def __post_init__(self) -> None:
        # lists from JSON or the command line become tuples, so settings stay hashable records
        object.__setattr__(self, "modes", tuple(self.modes))
        if not isinstance(self.direct, bool):
            object.__setattr__(self, "direct", tuple(self.direct))
        for name in ("spp", "max_depth", "batches"):
            _positive(name, getattr(self, name))
        if self.spectral_spp is not None:
            _positive("spectral_spp", self.spectral_spp)
        for name in ("spp", "spectral_spp"):
            if (getattr(self, name) or 0) % self.batches:
                raise RenderError(
                    f"render setting {name}={getattr(self, name)} with batches={self.batches}; "
                    f"expected {name} divisible by batches (each batch renders {name} / "
                    "batches samples)"
                )
        target, most = self.noise_target, self.max_batches
        if target is not None and not (isinstance(target, int | float) and 0 < target < 1):
            _refuse("noise_target", target, "a fraction in (0, 1), e.g. 0.02")
        if most is not None and (not isinstance(most, int) or most < self.batches):
            _refuse("max_batches", most, f"an integer >= batches ({self.batches})")
        if self.integrator not in INTEGRATORS:
            _refuse("integrator", self.integrator, f"one of {', '.join(INTEGRATORS)}")

    @property
    def batch_spp(self) -> int:
        """Samples per pixel of every pass of one batch, ``spp / batches``."""
        return self.spp // self.batches

    @property
    def spectral_batch_spp(self) -> int:
        """Samples per pixel of the spectral pass of one batch."""
        return (self.spp if self.spectral_spp is None else self.spectral_spp) // self.batches

    @property
    def per_light_modes(self) -> tuple[str, ...] | None:
        """The modes rendered light by light when they differ from :attr:`modes`."""
        return (self.share_mode,) if self.per_light and self.share_mode else None

    def all_modes(self) -> tuple[str, ...]:
        """Every mode named, the share mode included (for validation against the registry)."""
        return self.modes + ((self.share_mode,) if self.share_mode else ())

    def with_options(self, **changes: Any) -> RenderSettings:
        """A copy with some settings changed (validated like new settings)."""
        return replace(self, **changes)


@dataclass(frozen=True, eq=False)
class PassRequest:
    """What every Mitsuba pass of one batch shares, checked once: every pass (the band-path
    traversal, the diagonal passes, the spectral pass, the first-hit maps) takes this record.

    Attributes
    ----------
    batch_spp
        Samples per pixel of this pass (one batch's: :attr:`RenderSettings.batch_spp`, or
        :attr:`RenderSettings.spectral_batch_spp` for the spectral pass).
    seed
        The sampler seed (the batch's); every pass of a batch uses it, so passes trace the
        same paths (common random numbers).
    max_depth, variant
        As :class:`RenderSettings`'.
    progress
        Called with 1 after each Mitsuba pass (e.g. ``tqdm.update``), or ``None``.
    geometry
        :func:`spectrinsic.render.base.geometry.prepare_geometry` of the scene, if already
        computed (the batches of one scene share it).
    """

    batch_spp: int
    seed: int
    max_depth: int = 8
    variant: str | None = None
    progress: PassProgress | None = None
    geometry: Sequence[SurfaceGeometry] | None = None

    def __post_init__(self) -> None:
        _positive("batch_spp", self.batch_spp)
        _positive("max_depth", self.max_depth)

    @classmethod
    def of(
        cls,
        settings: RenderSettings,
        seed: int,
        progress: PassProgress | None = None,
        geometry: Sequence[SurfaceGeometry] | None = None,
    ) -> PassRequest:
        """The request of one batch of *settings* with sampler seed *seed*."""
        return cls(
            settings.batch_spp, seed, settings.max_depth, settings.variant, progress, geometry
        )

    def tick(self) -> None:
        """Report one finished Mitsuba pass to :attr:`progress`."""
        if self.progress is not None:
            self.progress(1)
