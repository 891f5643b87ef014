"""The studies registry: every study behind one protocol, and the one runner for all of them.

A study turns the command line's options into its own settings record, computes a result
without writing anything, formats it as text and writes its files:

>>> sorted(STUDIES)
['photometric', 'reconstruction-error', 'rendering', 'sim2real']
>>> get_study("photometric").settings(StudyOptions(seed=3)).seed
3

``spectrinsic study NAME`` is :func:`run_study` of ``STUDIES[NAME]``; a new study is one class
with the four methods below and one entry in :data:`STUDIES`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Protocol

from ..arrays import StepProgress
from ..errors import StudyError, validate_choice
from .photometric import (
    PhotometricResult,
    PhotometricSettings,
    format_photometric,
    run_photometric,
    write_photometric_outputs,
)
from .reconstruction import (
    ExtensionResult,
    TableResult,
    format_extension,
    format_table,
    reconstruction_table,
    run_extension,
    write_extension_outputs,
    write_table_outputs,
)
from .rendering import (
    RenderingResult,
    RenderingSettings,
    format_rendering,
    rendering_payload,
    run_rendering,
    write_rendering_outputs,
)
from .sim2real import (
    Sim2RealResult,
    Sim2RealSettings,
    format_sim2real,
    run_sim2real,
    write_sim2real,
)
from .sim2real import preset as sim2real_preset

__all__ = ["StudyOptions", "Study", "STUDIES", "get_study", "study_names", "StudyRun", "run_study"]


@dataclass(frozen=True)
class StudyOptions:
    """The options a user gives any study; each study reads the ones it has.

    Attributes
    ----------
    seed
        Root seed of random choices (photometric scenes, rendered illuminants and samplers).
    include_ie
        photometric: add the Image Engineering 2024 cameras of the data directory.
    camera_balance
        photometric: normalisation of the camera curves.
    extension
        reconstruction-error: also the extended sweep, beside Table 5.2.
    quality
        rendering: quality preset (:data:`spectrinsic.studies.rendering.QUALITIES`).
    preset
        sim2real: size preset (:data:`spectrinsic.studies.sim2real.PRESETS`); None: ``small``.
    """

    seed: int = 0
    include_ie: bool = False
    camera_balance: str = "equal-energy-white"
    extension: bool = True
    quality: str = "default"
    preset: str | None = None


class Study(Protocol):
    """One study: ``settings`` -> ``run`` -> ``format`` and ``write``."""

    @property
    def name(self) -> str:
        """The study's name on the command line."""

    @property
    def summary(self) -> str:
        """One line for ``--help``."""

    def settings(self, options: StudyOptions) -> Any:
        """The study's own settings record from the user's options."""

    def run(self, settings: Any, *, data_dir: str | None, progress: StepProgress | None) -> Any:
        """Compute the result (no files written)."""

    def format(self, result: Any) -> str:
        """The result as the text printed on stdout."""

    def write(self, result: Any, out_dir: Path) -> dict[str, Path]:
        """Write the result's files into *out_dir*; their paths by kind."""


@dataclass(frozen=True)
class _Reconstruction:
    """Thesis Table 5.2 and, unless left out, its extended sweep."""

    name: str = "reconstruction-error"
    summary: str = "reconstruction error of the diagonal model (thesis Table 5.2) and its extension"

    def settings(self, options: StudyOptions) -> bool:
        return options.extension

    def run(
        self, settings: bool, *, data_dir: str | None, progress: StepProgress | None
    ) -> tuple[TableResult, ExtensionResult | None]:
        table = reconstruction_table(data_dir=data_dir, progress=progress)
        return table, run_extension(data_dir=data_dir, progress=progress) if settings else None

    def format(self, result: tuple[TableResult, ExtensionResult | None]) -> str:
        table, ext = result
        return format_table(table) + ("" if ext is None else "\n\n" + format_extension(ext))

    def write(
        self, result: tuple[TableResult, ExtensionResult | None], out_dir: Path
    ) -> dict[str, Path]:
        table, ext = result
        paths = write_table_outputs(table, out_dir)
        if ext is not None:
            paths.update(
                {f"extended_{k}": v for k, v in write_extension_outputs(ext, out_dir).items()}
            )
        return paths


@dataclass(frozen=True)
class _Photometric:
    """Thesis Table 4.4: reflectance estimates of the photometric scenarios."""

    name: str = "photometric"
    summary: str = "angular error of the photometric scenarios SC1-SC4 (thesis Table 4.4)"

    def settings(self, options: StudyOptions) -> PhotometricSettings:
        return PhotometricSettings(
            seed=options.seed,
            include_ie=options.include_ie,
            camera_balance=options.camera_balance,  # type: ignore[arg-type]
        )

    def run(
        self, settings: PhotometricSettings, *, data_dir: str | None, progress: StepProgress | None
    ) -> PhotometricResult:
        return run_photometric(settings, data_dir=data_dir, progress=progress)

    def format(self, result: PhotometricResult) -> str:
        return format_photometric(result)

    def write(self, result: PhotometricResult, out_dir: Path) -> dict[str, Path]:
        return write_photometric_outputs(result, out_dir)


@dataclass(frozen=True)
class _Rendering:
    """The rendered study: colour error of diagonal renders with all bounces, and r."""

    name: str = "rendering"
    summary: str = (
        "colour error of rendered diagonal modes against the 31-band cube, and r (Eq. 5.8)"
    )

    def settings(self, options: StudyOptions) -> RenderingSettings:
        return RenderingSettings(quality=options.quality, seed=options.seed)

    def run(
        self, settings: RenderingSettings, *, data_dir: str | None, progress: StepProgress | None
    ) -> RenderingResult:
        return run_rendering(settings, data_dir=data_dir, progress=progress)

    def format(self, result: RenderingResult) -> str:
        return format_rendering(rendering_payload(result))

    def write(self, result: RenderingResult, out_dir: Path) -> dict[str, Path]:
        return write_rendering_outputs(result, out_dir)


@dataclass(frozen=True)
class _Sim2Real:
    """The sim-to-real study: the U-Net trained on matched sets, scored on MIT photographs."""

    name: str = "sim2real"
    summary: str = (
        "a U-Net trained on matched generated sets (spectral vs rgb3 image, coloured vs white "
        "lights, camera chain or not), scored on MIT photographs (needs torch)"
    )

    def settings(self, options: StudyOptions) -> Sim2RealSettings:
        return replace(sim2real_preset(options.preset or "small"), seed=options.seed)

    def run(
        self, settings: Sim2RealSettings, *, data_dir: str | None, progress: StepProgress | None
    ) -> Sim2RealResult:
        return run_sim2real(settings, data_dir=data_dir, progress=progress)

    def format(self, result: Sim2RealResult) -> str:
        return format_sim2real(result)

    def write(self, result: Sim2RealResult, out_dir: Path) -> dict[str, Path]:
        return write_sim2real(result, out_dir)


#: The studies, in the order ``--help`` and ``make study`` list them.
STUDIES: dict[str, Study] = {
    s.name: s for s in (_Reconstruction(), _Photometric(), _Rendering(), _Sim2Real())
}


def study_names() -> list[str]:
    """Names of the registered studies."""
    return list(STUDIES)


def get_study(name: str) -> Study:
    """The study called *name*; one-line :class:`StudyError` suggesting close names."""
    return STUDIES[validate_choice(name, STUDIES, "study", error=StudyError)]


@dataclass(frozen=True)
class StudyRun:
    """What :func:`run_study` did: the result, its text and the files written."""

    study: str
    result: Any
    text: str
    paths: dict[str, Path]


def run_study(
    name: str,
    out_dir: str | Path,
    options: StudyOptions | None = None,
    *,
    data_dir: str | None = None,
    progress: StepProgress | None = None,
) -> StudyRun:
    """Run study *name* with *options*: settings, compute, write into *out_dir*, format."""
    study = get_study(name)
    result = study.run(
        study.settings(options or StudyOptions()), data_dir=data_dir, progress=progress
    )
    paths = study.write(result, Path(out_dir))
    return StudyRun(study.name, result, study.format(result), paths)
