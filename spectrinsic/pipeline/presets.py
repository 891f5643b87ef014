"""Dataset build settings: the :class:`DatasetConfig` record, its hash and the named presets.

A config holds every setting that changes the files of a sample (resolution, samples per pixel,
render modes, passes, seed). Its hash (:meth:`DatasetConfig.config_hash`) is the SHA-256 of
canonical JSON of those settings, the preset name, spectrinsic's pixel version and the versions
of the software that computes the pixels (:func:`hashed_versions`); a sample folder is reused
only when the hash in its ``meta.json`` matches. How the build is run (workers, threads, scheduler, which samples) never enters it.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

from .. import provenance
from ..errors import DatasetError, RenderError, validate_choice
from ..gt_export import DEFAULT_CAMERAS
from ..gt_export.dataset.manifest import SPLIT_FRACTIONS, SplitFractions, check_split_fractions
from ..gt_export.layers import LayerSettings
from ..gt_export.layers.records import REFERENCE_MODES
from ..gt_export.sample import config_hash
from ..render.algebra.light_transport import diagonal_mode_names
from ..render.algebra.modes import RENDER_MODES
from ..render.settings import RenderSettings
from ..spectra.camera_model import camera_model
from ..spectra.user_spectra import portable_names, sensor_files_record
from ..spectra.working_space import DEFAULT_WORKING_SPACE, working_space
from .source_record import recorded_source

__all__ = [
    "DatasetConfig",
    "MAX_RELIGHT",
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
#: render (spectrinsic/render/band_path/traversal.py), not one render per light.
#: 4: the white-surface radiance is denoised as three broad bands (OIDN high) times per-band
#: shares, guided by normals and a depth grey marked clean (spectrinsic/gt_export/layers/denoise.py).
#: 5: each light's share is one float32 product (render/algebra/shares.py): at most one rounding.
#: 6: raw channels go to XYZ by chunked einsum, not BLAS (render/algebra/modes.py), an image's XYZ
#: is the float64 sum of its lights' (light_transport.py): one float32 rounding, BLAS-free.
#: 7: a non-power-of-two spp renders as power-of-two parts with their own seeds, averaged
#: (render/base/sample_split.py): bits independent of Dr.Jit's threads, other samples drawn.
#: 8: environment maps in one spectral pass (render/base/summed_envmap.py): other samples.
PIXELS_VERSION = 8
#: What of the installed software changes pixels, hence enters the config hash, and how much
#: of its version: the renderer exactly (its sampling changes between patch releases);
#: colour-science's data tables (CMFs, illuminants, cameras) by minor release; numpy by major
#: release (type promotion rules). Other packages and patch releases do not enter it, so a
#: fresh environment with the tested versions (constraints.txt) keeps a dataset complete.
HASHED_PACKAGES: dict[str, int | None] = {
    "mitsuba": None,
    "drjit": None,
    "colour-science": 2,
    "numpy": 1,
}


def hashed_versions() -> dict[str, str]:
    """The versions that enter the config hash: :data:`PIXELS_VERSION` and the versions of
    :data:`HASHED_PACKAGES` (:func:`spectrinsic.provenance.software_versions`), each cut to
    the parts that change pixels (``"absent"`` when a package is absent)."""
    installed = provenance.software_versions(HASHED_PACKAGES, python=False)
    out = {"spectrinsic-pixels": str(PIXELS_VERSION)}
    for name, parts in HASHED_PACKAGES.items():
        out[name] = (
            installed[name] if parts is None else ".".join(installed[name].split(".")[:parts])
        )
    return out


#: The render settings of a dataset unless a preset or option says otherwise (``spp`` has
#: none): every mode, each light alone (the illuminant map of multi-light scenes) through the
#: 1-pass ``rgb3`` mode, and the AOVs the ground truth is computed from.
DATASET_RENDER: dict[str, Any] = {
    "modes": _STANDARD_MODES,
    "per_light": True,
    "share_mode": "rgb3",
    "aovs": True,
}
#: Settings of :class:`RenderSettings` a dataset config takes (flat, beside its own); all but
#: ``integrator`` are recorded and hashed (:meth:`DatasetConfig.settings`).
RENDER_KEYS: tuple[str, ...] = (
    "spp",
    "spectral_spp",
    "max_depth",
    "modes",
    "per_light",
    "direct",
    "batches",
    "share_mode",
    "noise_target",
    "max_batches",
    "variant",
    "integrator",
)


#: Most relit variants per sample (``--relight N``): each is a whole sample folder written
#: from the transport, so the bound keeps a build's size within reach of its plan.
MAX_RELIGHT = 1000


def _check_relit_reference(relight: int, modes: tuple[str, ...]) -> None:
    """Relit variants keep their base sample's reference mode: with ``--relight``, the
    reference mode (the first of the render's modes in ``REFERENCE_MODES``) must be one the
    stored transport relights (a diagonal mode); the preview preset's ``spectral`` is not."""
    reference = next((m for m in REFERENCE_MODES if m in modes), None)
    diagonal = diagonal_mode_names(modes)
    if relight and reference is not None and reference not in diagonal:
        glossy = next((m for m in REFERENCE_MODES if m in diagonal), None)
        raise DatasetError(
            f"--relight {relight} with modes {list(modes)}: a matte sample's reference image "
            f"is the {reference!r} render, which the stored transport cannot relight (variants "
            "would come from another mode than their base samples)"
            + (f" (only glossy samples take {glossy!r} as reference)" if glossy else "")
            + "; use the default preset"
        )


@dataclass(frozen=True)
class DatasetConfig:
    """Settings of one dataset build.

    Attributes
    ----------
    preset
        Name of the preset this config started from (recorded and hashed).
    width, height
        Image size in pixels.
    render
        How every sample is rendered (:class:`~spectrinsic.render.settings.RenderSettings`):
        modes (``"spectral"`` is the physical reference), samples per pixel in total over the
        independent batches (two or more give the measured noise budget,
        ``meta.json["noise"]``), path depth, per-light renders with their share mode, direct
        light, adaptive batches, Mitsuba variant. The record written and hashed holds its
        settings flat (:data:`RENDER_KEYS`), the AOVs always on.
    write_cube
        Write the multispectral (31-band) cube of each sample.
    denoise
        Take shading, residual and illuminant from the OIDN-denoised irradiance (raw layers
        kept as ``shading_raw``/``residual_raw``).
    cameras
        Camera sensitivity names (``spectrinsic.spectra.get_sensors``) whose images and relative
        reflectances the ground truth also holds (they need the ``bands31`` cube); ``None``:
        :data:`spectrinsic.gt_export.DEFAULT_CAMERAS` when ``bands31`` is rendered, else none
        (see :meth:`resolved_cameras`).
    seed
        Root seed; each sample's seed is ``seed_from_key(seed, sample_id)``.
    source
        Where the scenes come from, as canonical JSON: ``None`` for the library layout,
        ``{"generator": ..., "count": ..., ...}`` or ``{"scenes": [...], ...}`` (see
        :func:`spectrinsic.pipeline.sample_plan.plan_samples`). Left out of the settings when
        ``None``, so library configs keep their hash.
    store_transport
        Keep each light's band transport for a flat unit spectrum (the single traversal's
        split by light; light by light only with ``integrator="passes"``) and store that
        per-light transport in each sample (``transport.exr``), so the sample can be relit
        exactly (:mod:`spectrinsic.gt_export.relight`). Left out of the settings when off, so
        other configs keep their hash. A dataset setting rather than a render one: it picks
        the renderer (:func:`~spectrinsic.render.transport_render.render_transport_batches`) and a
        file of the sample, not how a pass is rendered.
    relight
        Relit variants written per rendered sample (needs *store_transport*), each under light
        spectra drawn by :func:`spectrinsic.gt_export.relight.augment.draw_light_spectra`. Left
        out of the settings when 0.
    spectral_layers
        Write the per-band intrinsic layers of the 31-band cube in each sample
        (``spectral.exr``, :mod:`spectrinsic.gt_export.layers.spectral_intrinsics`); needs the
        ``bands31`` mode. Left out of the settings when off.
    working_space
        The RGB working space of the RGB layers (``--working-space``,
        :mod:`spectrinsic.spectra.working_space`): ``"acescg"`` (default; shading negatives
        kept) or ``"srgb"`` (linear sRGB, shading clipped: the layers of before). Hashed
        unless ``"srgb"``, so sRGB configs keep their hash.
    split_fractions
        ``(split, share)`` pairs of the scenes in the manifest's splits (default
        :data:`~spectrinsic.gt_export.dataset.manifest.SPLIT_FRACTIONS`, 80/10/10); with at least as
        many scenes as splits every split holds a scene. Not a setting of the samples (not
        hashed): a resumed build with other fractions rewrites only the manifest.
    camera
        A camera model to run every sample through (``--camera``, a name of
        :func:`spectrinsic.spectra.camera_model.camera_model`): raw mosaic, DNG, processed image
        and the ground truth in the processed linear space (:mod:`spectrinsic.gt_export.sample.sensor`).
        Needs ``bands31``; its sensitivities join *cameras*. Its whole model is hashed; left
        out of the settings when ``None``.
    """

    preset: str
    width: int
    height: int
    render: RenderSettings
    write_cube: bool = False
    denoise: bool = False
    cameras: tuple[str, ...] | None = None
    seed: int = 0
    source: str | None = None
    store_transport: bool = False
    relight: int = 0
    spectral_layers: bool = False
    working_space: str = DEFAULT_WORKING_SPACE
    split_fractions: SplitFractions = SPLIT_FRACTIONS
    camera: str | None = None

    def __post_init__(self) -> None:
        if self.cameras is not None:  # a list from JSON or the command line
            object.__setattr__(self, "cameras", tuple(self.cameras))
        for name in ("width", "height"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < 1:
                raise DatasetError(f"dataset setting {name}={value!r}; expected a positive integer")
        if not self.render.modes:
            raise DatasetError("dataset setting modes=(); expected at least one render mode")
        for mode in self.render.all_modes():
            validate_choice(mode, RENDER_MODES, "render mode", error=DatasetError)
        if not isinstance(self.seed, int) or self.seed < 0:
            raise DatasetError(f"dataset seed {self.seed!r}; expected a non-negative integer")
        object.__setattr__(self, "split_fractions", check_split_fractions(self.split_fractions))
        working_space(self.working_space, "--working-space")  # the one check of a name
        self._check_transport()
        if self.camera is not None:
            camera_model(self.camera)  # a one-line CameraModelError for an unknown name
            if "bands31" not in self.render.modes:
                raise DatasetError(
                    f"--camera {self.camera} with modes {list(self.render.modes)}: the camera "
                    "chain needs the 'bands31' mode (use a preset that renders it, e.g. default)"
                )

    def _check_transport(self) -> None:
        modes, direct = self.render.modes, self.render.direct
        if self.store_transport and not diagonal_mode_names(modes):
            raise DatasetError(
                f"--store-transport with modes {list(modes)}: the transport needs a "
                "diagonal mode (rgb3, rgb6 or bands31)"
            )
        if self.store_transport and direct and "spectral" not in modes:
            raise DatasetError(
                "--store-transport with --direct needs the 'spectral' mode (the "
                "diagonal modes are composed from the transport, not rendered directly)"
            )
        relight = self.relight
        if isinstance(relight, bool) or not isinstance(relight, int) or relight < 0:
            raise DatasetError(
                f"dataset setting relight={self.relight!r}; expected a non-negative integer"
            )
        if self.spectral_layers and "bands31" not in self.render.modes:
            raise DatasetError(
                f"--spectral-layers with modes {list(self.render.modes)}: the spectral layers "
                "need the 31-band cube (mode bands31, as in the default preset)"
            )
        if relight > MAX_RELIGHT:
            raise DatasetError(
                f"--relight {relight}: at most {MAX_RELIGHT} relit variants per sample (each "
                "is a full sample folder)"
            )
        if self.relight and not self.store_transport:
            raise DatasetError(
                f"--relight {self.relight} needs --store-transport (relit variants are "
                "composed from the stored transport)"
            )
        _check_relit_reference(self.relight, tuple(self.render.modes))

    @classmethod
    def from_settings(cls, preset: str, **settings: Any) -> DatasetConfig:
        """A config from flat settings (those of :meth:`settings`, ``cameras`` unresolved):
        the render ones (:data:`RENDER_KEYS`) over :data:`DATASET_RENDER`, the others fields;
        one-line :class:`~spectrinsic.errors.DatasetError` on a bad or unknown one.

        >>> c = DatasetConfig.from_settings("tiny", width=8, height=8, spp=2, max_depth=3)
        >>> c.render.spp, c.render.max_depth, c.render.share_mode
        (2, 3, 'rgb3')
        """
        known = set(RENDER_KEYS) | {f.name for f in fields(cls)} - {"preset", "render"}
        unknown = set(settings) - known
        if unknown:
            raise DatasetError(
                f"unknown dataset setting(s) {sorted(unknown)}; expected some of {sorted(known)}"
            )
        if "spp" not in settings:
            raise DatasetError(
                "dataset settings without spp; expected samples per pixel, e.g. spp=16"
            )
        render = {k: settings.pop(k) for k in RENDER_KEYS if k in settings}
        try:
            settings["render"] = RenderSettings(**{**DATASET_RENDER, **render})
        except RenderError as exc:
            raise DatasetError(str(exc).replace("render setting", "dataset setting")) from None
        return cls(preset=preset, **settings)

    def with_options(self, **changes: Any) -> DatasetConfig:
        """A copy with some flat settings changed (validated like a new config)."""
        current = {
            f.name: getattr(self, f.name)
            for f in fields(self)
            if f.name not in ("preset", "render")
        }
        current.update({k: getattr(self.render, k) for k in RENDER_KEYS})
        preset = changes.pop("preset", self.preset)
        return DatasetConfig.from_settings(preset, **{**current, **changes})

    def settings(self) -> dict[str, Any]:
        """The settings that change output files, as JSON-ready values (no preset name)."""
        r = self.render
        d: dict[str, Any] = {
            "width": self.width,
            "height": self.height,
            "spp": r.spp,
            "spectral_spp": r.spectral_spp,
            "max_depth": r.max_depth,
            "modes": list(r.modes),
            "per_light": r.per_light,
            "direct": r.direct if isinstance(r.direct, bool) else list(r.direct),
            "write_cube": self.write_cube,
            "batches": r.batches,
            "denoise": self.denoise,
            "share_mode": r.share_mode,
            "noise_target": r.noise_target,
            "max_batches": r.max_batches,
            "cameras": portable_names(list(self.resolved_cameras())),  # sensor CSVs by name
            "variant": r.variant,
            "seed": self.seed,
        }
        if self.source is not None:  # scene files by name: the same hash on any machine
            d["source"] = recorded_source(self.source)
        if self.store_transport:  # off: out of the hash, as before these settings existed
            d["store_transport"] = True
        if self.relight:
            d["relight"] = self.relight
        if self.camera is not None:  # off: out of the hash
            d["camera"] = portable_names(camera_model(self.camera).settings())
        d.update(sensor_files_record([*self.resolved_cameras(), self.camera or ""]))
        if self.spectral_layers:  # off: out of the hash, as before it existed
            d["spectral_layers"] = True
        if self.working_space != "srgb":  # srgb: the layers of before, their hash
            d["working_space"] = self.working_space
        return d

    def resolved_cameras(self) -> tuple[str, ...]:
        """The camera sensor sets exported, with ``cameras=None`` resolved."""
        if self.cameras is not None:
            cams = tuple(self.cameras)
        else:
            cams = tuple(DEFAULT_CAMERAS) if "bands31" in self.render.modes else ()
        if self.camera is not None:  # the camera chain runs on its own camera's image
            sensor = camera_model(self.camera).sensitivities
            cams += () if sensor in cams else (sensor,)
        return cams

    def layer_settings(self, data_dir: str | None = None) -> LayerSettings:
        """The :class:`LayerSettings` of every sample of this dataset (*data_dir*: the build's)."""
        camera = camera_model(self.camera) if self.camera else None
        flags = (self.write_cube, self.denoise, self.spectral_layers)
        space = working_space(self.working_space)
        return LayerSettings(self.resolved_cameras(), camera, *flags, space, data_dir)

    def to_dict(self) -> dict[str, Any]:
        """The record written with the dataset (``export_sample``, manifest): preset name,
        settings and :func:`hashed_versions`. Its canonical hash is :meth:`config_hash`."""
        return {"preset": self.preset, **self.settings(), "software": hashed_versions()}

    def config_hash(self) -> str:
        """SHA-256 (hex) of the canonical JSON of :meth:`to_dict`.

        Computed by :func:`spectrinsic.gt_export.sample.config_hash`, the function that stamps
        ``meta.json``, so the hash a build checks is the hash its samples carry.
        """
        return config_hash(self.to_dict())


#: Named presets. Times were measured on this project's 2-core reference machine
#: (``make bench``). ``direct`` stays off: the ground truth does not use the direct-only
#: renders, which would double every pass.
PRESETS: dict[str, DatasetConfig] = {
    # The whole set in about a minute: a look at the layout, not data to learn from. Without
    # the cube, shading comes from the spectral render's XYZ (a 3-band estimate).
    "preview": DatasetConfig.from_settings(
        "preview",
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
    # maps; two batches measure the noise. The reference image, the ground truth and the
    # transport come from the traversal, 2 x 160 spp; the spectral image, which only measures
    # the diagonal modes' spectral error, keeps 2 x 32 (per sample it costs as much as the
    # traversal of all 40 bands). Against a 16384-spp reference of a room crop (its own noise
    # 1.2 % median; make bench, bench_crop_reference.json) the denoised shading is off by
    # median / p95 1.96 % / 12.0 % at 2 x 32 spp, 1.76 % / 8.7 % at 2 x 96 and 1.62 % / 7.8 %
    # at 2 x 160: samples buy the tail slowly. The whole set built and checked in 610 s,
    # 777 s and 1119 s on an idle machine (make dataset); 2 x 192 was on course for 22 min.
    "default": DatasetConfig.from_settings(
        "default",
        width=256,
        height=256,
        spp=320,
        spectral_spp=64,
        max_depth=6,
        per_light=True,
        batches=2,
        denoise=True,
    ),
    # Publication quality, for a GPU (variant cuda) or a cluster (--scheduler).
    "paper": DatasetConfig.from_settings(
        "paper",
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
