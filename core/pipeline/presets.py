"""Dataset build settings: the :class:`DatasetConfig` record, its hash and the named presets.

A config holds every setting that changes the files of a sample (resolution, samples per pixel,
render modes, passes, seed). Its hash (:meth:`DatasetConfig.config_hash`) is the SHA-256 of
canonical JSON of those settings, the preset name, spectrinsic's pixel version and the versions
of the software that computes the pixels (:func:`hashed_versions`); a sample folder is reused
only when the hash in its ``meta.json`` matches. How the build is run (workers, threads, scheduler, which samples) never enters it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from typing import Any

from spectrinsic import provenance
from spectrinsic.errors import DatasetError, validate_choice
from spectrinsic.render.modes import RENDER_MODES

__all__ = [
    "DatasetConfig",
    "PRESETS",
    "HASHED_PACKAGES",
    "PIXELS_VERSION",
    "preset_names",
    "get_preset",
    "hashed_versions",
]

#: Modes of the default and paper presets: the reference cube, the 3-/6-sensor approximations
#: it measures, and the spectral Monte Carlo render.
_STANDARD_MODES: tuple[str, ...] = ("spectral", "rgb3", "rgb6", "bands31")

#: Version of spectrinsic's own computation of pixels and ground truth. Bump it whenever a
#: change alters any written value (a new or changed layer, formula, sampling or file layout),
#: so existing datasets are rebuilt; a release that changes none keeps old datasets valid.
#: 3: diagonal modes from one band-path traversal; per-light images are shares of the full
#: render (render/single.py), not one render per light.
PIXELS_VERSION = 3
#: What of the installed software changes pixels, hence enters the config hash, and how much
#: of its version: the renderer exactly (its sampling changes between patch releases);
#: colour-science's data tables (CMFs, illuminants, cameras) by minor release; numpy by major
#: release (type promotion rules). Other packages and patch releases do not enter it, so a
#: fresh environment with the tested versions (constraints.txt) keeps a dataset complete.
HASHED_PACKAGES: dict[str, int | None] = {"mitsuba": None, "drjit": None, "colour-science": 2, "numpy": 1}


def hashed_versions() -> dict[str, str]:
    """The versions that enter the config hash: :data:`PIXELS_VERSION` and the versions of
    :data:`HASHED_PACKAGES` (:func:`spectrinsic.provenance.software_versions`), each cut to
    the parts that change pixels (``"absent"`` when a package is absent)."""
    installed = provenance.software_versions(HASHED_PACKAGES, python=False)
    out = {"spectrinsic-pixels": str(PIXELS_VERSION)}
    for name, parts in HASHED_PACKAGES.items():
        out[name] = installed[name] if parts is None else ".".join(installed[name].split(".")[:parts])
    return out


@dataclass(frozen=True)
class DatasetConfig:
    """Settings of one dataset build.

    Attributes
    ----------
    preset
        Name of the preset this config started from (recorded and hashed).
    width, height
        Image size in pixels.
    spp
        Samples per pixel of every render pass.
    max_depth
        Maximum path length (Mitsuba's ``max_depth``; 2 = direct light only).
    modes
        Render modes, names registered in :data:`spectrinsic.render.modes.RENDER_MODES`;
        ``"spectral"`` is the physical reference.
    per_light
        Also render each light alone (needed for the per-pixel illuminant map of multi-light
        scenes).
    direct
        Also render direct illumination only.
    write_cube
        Write the multispectral (31-band) cube of each sample.
    batches
        Independent batches the *spp* samples are split into (each ``spp / batches`` samples,
        its own seed, common random numbers across modes inside it). Two or more give the
        measured noise budget (``meta.json["noise"]``).
    denoise
        Take shading, residual and illuminant from the OIDN-denoised irradiance (raw layers
        kept as ``shading_raw``/``residual_raw``).
    noise_target
        Adaptive sampling: add batches of ``spp / batches`` samples while the median relative
        standard error of the image is above this (e.g. 0.02), up to *max_batches*.
    max_batches
        Cap of the adaptive batches (default ``4 * batches``).
    share_mode
        With *per_light*: render only this 1-pass mode light by light, for the light shares,
        and every other mode once with all lights (``None``: every mode light by light).
    cameras
        Camera sensitivity names (``spectrinsic.spectra.get_sensors``) whose images and relative
        reflectances the ground truth also holds (they need the ``bands31`` cube); ``None``:
        :data:`spectrinsic.gt_export.DEFAULT_CAMERAS` when ``bands31`` is rendered, else none
        (see :meth:`resolved_cameras`).
    variant
        Mitsuba variant, or ``None`` for the render package's automatic choice.
    seed
        Root seed; each sample's seed is ``seed_from_key(seed, sample_id)``.
    source
        Where the scenes come from, as canonical JSON: ``None`` for the library layout,
        ``{"generator": ..., "count": ..., ...}`` or ``{"scenes": [...], ...}`` (see
        :func:`spectrinsic.pipeline.dataset.plan_samples`). Left out of the settings when ``None``, so
        library configs keep their hash.
    """

    preset: str
    width: int
    height: int
    spp: int
    max_depth: int = 8
    modes: tuple[str, ...] = _STANDARD_MODES
    per_light: bool = True
    direct: bool = False
    write_cube: bool = False
    batches: int = 1
    denoise: bool = False
    share_mode: str | None = "rgb3"
    noise_target: float | None = None
    max_batches: int | None = None
    cameras: tuple[str, ...] | None = None
    variant: str | None = None
    seed: int = 0
    source: str | None = None

    def __post_init__(self) -> None:
        # lists from JSON or the command line become tuples, so configs stay hashable records
        object.__setattr__(self, "modes", tuple(self.modes))
        if self.cameras is not None:
            object.__setattr__(self, "cameras", tuple(self.cameras))
        for name in ("width", "height", "spp", "max_depth", "batches"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < 1:
                raise DatasetError(f"dataset setting {name}={value!r}; expected a positive integer")
        if self.noise_target is not None and not (isinstance(self.noise_target, int | float)
                                                  and 0 < self.noise_target < 1):
            raise DatasetError(f"dataset setting noise_target={self.noise_target!r}; expected a "
                               "fraction in (0, 1), e.g. 0.02")
        if self.max_batches is not None and (not isinstance(self.max_batches, int)
                                             or self.max_batches < self.batches):
            raise DatasetError(f"dataset setting max_batches={self.max_batches!r}; expected an "
                               f"integer >= batches ({self.batches})")
        if self.spp % self.batches:
            raise DatasetError(
                f"dataset setting spp={self.spp} with batches={self.batches}; expected spp "
                "divisible by batches (each batch renders spp / batches samples)"
            )
        if not self.modes:
            raise DatasetError("dataset setting modes=(); expected at least one render mode")
        for mode in self.modes + ((self.share_mode,) if self.share_mode else ()):
            validate_choice(mode, RENDER_MODES, "render mode", error=DatasetError)
        if not isinstance(self.seed, int) or self.seed < 0:
            raise DatasetError(f"dataset seed {self.seed!r}; expected a non-negative integer")

    def with_options(self, **changes: Any) -> DatasetConfig:
        """A copy with some settings changed (validated like a new config)."""
        unknown = set(changes) - set(self.settings()) - {"preset", "source"}
        if unknown:
            raise DatasetError(
                f"unknown dataset setting(s) {sorted(unknown)}; expected some of "
                f"{sorted(self.settings())}"
            )
        return replace(self, **changes)

    def settings(self) -> dict[str, Any]:
        """The settings that change output files, as JSON-ready values (no preset name)."""
        d = asdict(self)
        d.pop("preset")
        d["modes"] = list(self.modes)
        d["cameras"] = list(self.resolved_cameras())
        if self.source is None:
            d.pop("source")
        return d

    def resolved_cameras(self) -> tuple[str, ...]:
        """The camera sensor sets exported, with ``cameras=None`` resolved."""
        if self.cameras is not None:
            return tuple(self.cameras)
        if "bands31" not in self.modes:
            return ()
        from spectrinsic.gt_export import DEFAULT_CAMERAS

        return tuple(DEFAULT_CAMERAS)

    def to_dict(self) -> dict[str, Any]:
        """The record written with the dataset (``export_sample``, manifest): preset name,
        settings and :func:`hashed_versions`. Its canonical hash is :meth:`config_hash`."""
        return {"preset": self.preset, **self.settings(), "software": hashed_versions()}

    def config_hash(self) -> str:
        """SHA-256 (hex) of the canonical JSON of :meth:`to_dict`.

        Computed by :func:`spectrinsic.gt_export.writer.config_hash`, the function that stamps
        ``meta.json``, so the hash a build checks is the hash its samples carry.
        """
        from spectrinsic.gt_export.writer import config_hash

        return config_hash(self.to_dict())


#: Named presets. Times were measured on this project's 2-core reference machine
#: (``make bench``). ``direct`` stays off: the ground truth does not use the direct-only
#: renders, which would double every pass.
PRESETS: dict[str, DatasetConfig] = {
    # The whole set in about a minute: a look at the layout, not data to learn from. Without
    # the cube, shading comes from the spectral render's XYZ (a 3-band estimate).
    "preview": DatasetConfig(
        preset="preview",
        width=48,
        height=48,
        spp=4,
        max_depth=4,
        modes=("spectral", "rgb3"),
        per_light=True,
        batches=2,
        denoise=True,
    ),
    # The thesis layout (68 samples) at 256² in <= 20 minutes on 2 cores: every render mode,
    # so the reference image is the 31-band cube and the 3-/6-sensor approximations carry error
    # maps; two batches of 8 spp measure the noise. The denoised shading's median error
    # against a 16x-spp reference is measured by make bench (bench_ground_truth.json).
    "default": DatasetConfig(
        preset="default",
        width=256,
        height=256,
        spp=16,
        max_depth=6,
        per_light=True,
        batches=2,
        denoise=True,
    ),
    # Publication quality, for a GPU (variant cuda) or a cluster (--scheduler).
    "paper": DatasetConfig(
        preset="paper",
        width=512,
        height=512,
        spp=1024,
        max_depth=8,
        per_light=True,
        write_cube=True,
        batches=4,
        denoise=True,
    ),
}


def preset_names() -> list[str]:
    """Names of the presets, fastest first."""
    return list(PRESETS)


def get_preset(name: str, *, seed: int = 0) -> DatasetConfig:
    """Return the preset called *name* with root seed *seed*.

    Raises
    ------
    SpectrinsicError
        If *name* is not a preset (the message suggests close names).
    """
    validate_choice(name, PRESETS, "dataset preset", error=DatasetError)
    return PRESETS[name].with_options(seed=seed)
