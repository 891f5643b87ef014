"""The camera record: what turns a camera's linear RGB into the raw numbers it would have written.

A :class:`CameraModel` holds the sensitivities (any sensor set of the registry:
``camera:Nikon 5100 (NPL)``, ``camera:Nikon D3`` from a data directory, ``csv:/path``), the
exposure, the sensor's photon-transfer figures (conversion gain in e⁻/DN, full well, read
noise, dark current, fixed-pattern noise), the ADC (bits, black level), the colour filter array
and the image-processing choices. :data:`CAMERA_PRESETS` holds a few real cameras with the source
of every number; :func:`camera_model` resolves a preset name, or a sensor-set name with the
generic figures of :data:`GENERIC_FIGURES`.

The noise model (:mod:`spectrinsic.spectra.camera_noise`) is the standard photon-transfer model
(EMVA 1288; Janesick 2007): signal electrons ``e = Poisson(k · q · (1 + PRNU))`` plus dark
current, Gaussian read noise of ``read_noise_e`` electrons, optional row noise and a heavy
Tukey-lambda tail (the ELD model: Wei et al., CVPR 2020), clipped at ``full_well_e``, converted
to DN at ``1 / gain`` DN per electron and quantised. Its variance in DN above black is
``mean / gain + (read² + row²) / gain² + 1/12`` below saturation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np

from ..errors import SpectrinsicError, did_you_mean
from .records import SensorSet
from .registry import get_sensors, get_spectrum

__all__ = [
    "CFA_PATTERNS",
    "DEMOSAIC_METHODS",
    "WHITE_BALANCES",
    "TONE_CURVES",
    "CameraModel",
    "CameraModelError",
    "CAMERA_PRESETS",
    "GENERIC_FIGURES",
    "camera_model",
    "camera_model_names",
    "PRESET_ALIASES",
    "camera_sensors",
]

#: Bayer layouts, read row by row over the 2 × 2 tile (colour-demosaicing's names).
CFA_PATTERNS: tuple[str, ...] = ("RGGB", "BGGR", "GRBG", "GBRG")
#: Demosaicking algorithms of colour-demosaicing.
DEMOSAIC_METHODS: tuple[str, ...] = ("bilinear", "malvar2004", "menon2007")
#: ``none``: camera RGB as recorded; ``grey-world``: equal channel means; ``illuminant``: the
#: known light of the ground truth (its white made neutral).
WHITE_BALANCES: tuple[str, ...] = ("none", "grey-world", "illuminant")
#: ``srgb``: the IEC 61966-2-1 encoding; ``gamma2.2``: a pure power; ``linear``: none.
TONE_CURVES: tuple[str, ...] = ("srgb", "gamma2.2", "linear")


class CameraModelError(SpectrinsicError, ValueError):
    """A camera model or camera name that cannot be used."""


@dataclass(frozen=True)
class CameraModel:
    """One camera: sensitivities, exposure, sensor, ADC, CFA and image processing.

    Attributes
    ----------
    name
        Preset name or the sensor-set name it was made from.
    sensitivities
        Registry sensor set of the three CFA colours (R, G, B), e.g. ``"camera:Nikon 5100 (NPL)"``.
    gain_e_per_dn
        Conversion gain at ``iso_base``, electrons per DN (the slope of the photon-transfer
        curve in DN is its inverse).
    full_well_e
        Electrons at which a pixel saturates.
    read_noise_e
        Standard deviation of the Gaussian read noise at ``iso_base``, electrons.
    adc_bits
        ADC bit depth; raw values lie in ``[0, 2**adc_bits - 1]``.
    black_level_dn
        Offset added before quantisation, DN.
    cfa
        Bayer layout (:data:`CFA_PATTERNS`).
    iso, iso_base
        The ISO used and the sensor's base ISO: the gain in e⁻/DN is
        ``gain_e_per_dn · iso_base / iso`` (analogue gain; read noise in electrons kept).
    exposure_target
        Fraction of the full well the metered luminance reaches (an auto exposure, as a camera
        meters: :func:`spectrinsic.spectra.camera_chain.exposure_scale`); 0.18, middle grey, by
        default. Used when ``electrons_per_unit`` is ``None``.
    electrons_per_unit
        A fixed exposure instead: electrons per unit of the camera image (render units), i.e.
        the product of shutter time, aperture area and quantum efficiency for this render.
    exposure_time_s
        Shutter time, seconds (multiplies the dark current).
    dark_current_e_per_s
        Mean dark current, electrons per second (Poisson, like the signal).
    prnu
        Photo-response non-uniformity: relative standard deviation of a pixel's gain (fixed
        per camera: seeded by ``fixed_pattern_seed``).
    dsnu_e
        Dark-signal non-uniformity: standard deviation of a fixed offset, electrons.
    row_noise_e
        Standard deviation of a per-row offset redrawn each frame, electrons (ELD's row term).
    tail_lambda, tail_scale_e
        ELD's heavy read-noise tail: a Tukey-lambda variate of shape ``tail_lambda`` and scale
        ``tail_scale_e`` electrons replaces the Gaussian read noise when ``tail_lambda`` is set.
    fixed_pattern_seed
        Seed of the fixed-pattern maps (PRNU, DSNU): one camera body, the same in every sample.
    demosaic, white_balance, colour_matrix, tone_curve, output_bits
        Image processing: :data:`DEMOSAIC_METHODS`, :data:`WHITE_BALANCES`, whether the
        camera → XYZ → linear sRGB matrix fitted from the curves is applied, :data:`TONE_CURVES`
        and the bit depth (8 or 16) of the processed image.
    sources
        ``(field, citation)`` pairs: where each number comes from.
    """

    name: str
    sensitivities: str
    gain_e_per_dn: float
    full_well_e: float
    read_noise_e: float
    adc_bits: int = 14
    black_level_dn: int = 0
    cfa: str = "RGGB"
    iso: float = 100.0
    iso_base: float = 100.0
    exposure_target: float = 0.18
    electrons_per_unit: float | None = None
    exposure_time_s: float = 0.01
    dark_current_e_per_s: float = 0.0
    prnu: float = 0.0
    dsnu_e: float = 0.0
    row_noise_e: float = 0.0
    tail_lambda: float | None = None
    tail_scale_e: float = 0.0
    fixed_pattern_seed: int = 0
    demosaic: str = "malvar2004"
    white_balance: str = "illuminant"
    colour_matrix: bool = True
    tone_curve: str = "srgb"
    output_bits: int = 8
    sources: tuple[tuple[str, str], ...] = field(default=(), compare=False)

    def __post_init__(self) -> None:
        self._check_numbers()
        positive = {
            "gain_e_per_dn": self.gain_e_per_dn,
            "full_well_e": self.full_well_e,
            "iso": self.iso,
            "iso_base": self.iso_base,
        }
        for key, value in positive.items():
            if not value > 0:
                raise CameraModelError(f"camera {self.name!r}: {key} {value!r}: expected > 0")
        nonneg = {
            "read_noise_e": self.read_noise_e,
            "black_level_dn": self.black_level_dn,
            "exposure_time_s": self.exposure_time_s,
            "dark_current_e_per_s": self.dark_current_e_per_s,
            "prnu": self.prnu,
            "dsnu_e": self.dsnu_e,
            "row_noise_e": self.row_noise_e,
            "tail_scale_e": self.tail_scale_e,
        }
        for key, value in nonneg.items():
            if not value >= 0:
                raise CameraModelError(f"camera {self.name!r}: {key} {value!r}: expected >= 0")
        self._check_choices()

    def _check_numbers(self) -> None:
        """Every number finite (an infinite gain or exposure would give NaN raw values far
        downstream); the integers integers (``adc_bits`` 12.5 has no ADC maximum); PRNU, a
        relative standard deviation of gain, in [0, 1) (at 1 a pixel's gain is as likely
        negative as not)."""
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                continue
            if not math.isfinite(value):
                raise CameraModelError(
                    f"camera {self.name!r}: {f.name} {value!r}: expected a finite number"
                )
        for key in ("adc_bits", "black_level_dn", "output_bits", "fixed_pattern_seed"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, int | np.integer):
                raise CameraModelError(
                    f"camera {self.name!r}: {key} {value!r}: expected an integer"
                )
        if not 0 <= self.prnu < 1:
            raise CameraModelError(f"camera {self.name!r}: prnu {self.prnu!r}: expected [0, 1)")

    def _check_choices(self) -> None:
        if not 8 <= self.adc_bits <= 16:
            raise CameraModelError(f"camera {self.name!r}: adc_bits {self.adc_bits}: expected 8-16")
        if self.black_level_dn >= 2**self.adc_bits - 1:
            raise CameraModelError(
                f"camera {self.name!r}: black_level_dn {self.black_level_dn}: expected below "
                f"the ADC maximum {2**self.adc_bits - 1}"
            )
        if self.white_level_dn <= self.black_level_dn:
            raise CameraModelError(
                f"camera {self.name!r}: a full well of {self.full_well_e:g} e- at "
                f"{self.gain:g} e-/DN is under one DN above black; expected a gain below the "
                "full well"
            )
        if self.output_bits not in (8, 16):
            raise CameraModelError(
                f"camera {self.name!r}: output_bits {self.output_bits}: expected 8 or 16"
            )
        if not 0 < self.exposure_target <= 1:
            raise CameraModelError(
                f"camera {self.name!r}: exposure_target {self.exposure_target}: expected (0, 1]"
            )
        if self.electrons_per_unit is not None and not self.electrons_per_unit > 0:
            raise CameraModelError(
                f"camera {self.name!r}: electrons_per_unit {self.electrons_per_unit}: expected > 0"
            )
        for key, value, allowed in (
            ("cfa", self.cfa, CFA_PATTERNS),
            ("demosaic", self.demosaic, DEMOSAIC_METHODS),
            ("white_balance", self.white_balance, WHITE_BALANCES),
            ("tone_curve", self.tone_curve, TONE_CURVES),
        ):
            if value not in allowed:
                raise CameraModelError(
                    f"camera {self.name!r}: {key} {value!r}: expected one of {', '.join(allowed)}"
                )

    @property
    def gain(self) -> float:
        """Conversion gain at :attr:`iso`, electrons per DN."""
        return self.gain_e_per_dn * self.iso_base / self.iso

    @property
    def white_level_dn(self) -> int:
        """The largest raw value, DN: the full well above black, or the ADC maximum."""
        top = 2**self.adc_bits - 1
        return int(min(top, self.black_level_dn + round(self.full_well_e / self.gain)))

    def with_options(self, **changes: object) -> CameraModel:
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)  # type: ignore[arg-type]

    def settings(self) -> dict[str, object]:
        """Plain data of every field (recorded in ``meta.json`` and in the config hash)."""
        out: dict[str, object] = {
            k: getattr(self, k) for k in self.__dataclass_fields__ if k != "sources"
        }
        out["sources"] = dict(self.sources)
        return out


_BJANES = (
    "B. Janes, 'Sensorgen data for D800e', Luminous Landscape forum, 20 Feb 2013: photon "
    "transfer of the Nikon D800E at ISO 100 (slope 0.2287 DN/e-, read noise 4.13 e-, "
    "saturation 15735 DN)"
)
_NPL = "Darrodi et al. 2015 (NPL), Nikon D5100, via colour-science"
_JIANG = "Jiang, Liu, Gu & Süsstrunk, WACV 2013 (data directory)"
_MARTIN = "E. Martin, 'D3 sensor efficiency', dpreview forum post 25663276, 2008"
_CLAFF = "B. Claff, Nikonians forum 4 Mar 2008 (photonstophotos.net): D3 14-bit read noise"

#: Figures used for a sensor set named without a preset: those of the Nikon D800E at ISO 100.
GENERIC_FIGURES: dict[str, float] = {
    "gain_e_per_dn": 3.46,
    "full_well_e": 54503.0,
    "read_noise_e": 4.13,
}

#: Real cameras, every number with its source, each named by the slug of its sensor set's name,
#: so one name runs through preset, files and layers: ``--camera nikon-5100-npl`` writes
#: ``sensor-nikon-5100-npl.*`` with layers ``raw_sensor/Nikon 5100 (NPL)``. The NPL curves belong to a Nikon D5100; no
#: photon-transfer measurement of that body is cited here, so its preset borrows those of the
#: D800E (a Nikon of the same sensor generation), as its sources say.
CAMERA_PRESETS: dict[str, CameraModel] = {
    "nikon-5100-npl": CameraModel(
        name="nikon-5100-npl",
        sensitivities="camera:Nikon 5100 (NPL)",
        adc_bits=14,
        gain_e_per_dn=GENERIC_FIGURES["gain_e_per_dn"],
        full_well_e=GENERIC_FIGURES["full_well_e"],
        read_noise_e=GENERIC_FIGURES["read_noise_e"],
        sources=(
            ("sensitivities", _NPL),
            ("gain_e_per_dn", "1/0.2287 = 3.46 e-/DN, borrowed from the D800E: " + _BJANES),
            ("full_well_e", "15735 DN x 3.46 = 54503 e-, borrowed from the D800E: " + _BJANES),
            ("read_noise_e", "borrowed from the D800E: " + _BJANES),
            ("adc_bits", "14-bit NEF"),
        ),
    ),
    "nikon-d3": CameraModel(
        name="nikon-d3",
        sensitivities="camera:Nikon D3",
        gain_e_per_dn=round(53400.0 / 16383.0, 4),
        full_well_e=53400.0,
        read_noise_e=round(4.73 * 53400.0 / 16383.0, 2),
        adc_bits=14,
        iso=200.0,
        iso_base=200.0,
        sources=(
            ("sensitivities", _JIANG),
            ("full_well_e", "53400 e- at ISO 200: " + _MARTIN),
            ("gain_e_per_dn", "53400 e- / 16383 DN, assuming the well fills the 14-bit range"),
            ("read_noise_e", "4.73 DN at ISO 200 x the gain: " + _CLAFF),
        ),
    ),
}


#: Former preset names, still accepted (issue 47 renamed the preset after its sensor set).
PRESET_ALIASES: dict[str, str] = {"nikon-d5100-npl": "nikon-5100-npl"}


def camera_model_names() -> list[str]:
    """The preset names (:data:`CAMERA_PRESETS`)."""
    return list(CAMERA_PRESETS)


def camera_model(name: str) -> CameraModel:
    """A preset by name, or a registry sensor set (``camera:…``, ``csv:…``) with
    :data:`GENERIC_FIGURES`; anything else raises :class:`CameraModelError` (one line)."""
    name = PRESET_ALIASES.get(name, name)
    if name in CAMERA_PRESETS:
        return CAMERA_PRESETS[name]
    if name.startswith(("camera:", "csv:")):
        return CameraModel(
            name=name,
            sensitivities=name,
            gain_e_per_dn=GENERIC_FIGURES["gain_e_per_dn"],
            full_well_e=GENERIC_FIGURES["full_well_e"],
            read_noise_e=GENERIC_FIGURES["read_noise_e"],
            sources=(
                ("sensitivities", name),
                ("gain_e_per_dn, full_well_e, read_noise_e", "generic: " + _BJANES),
            ),
        )
    hint = did_you_mean(name, CAMERA_PRESETS)
    raise CameraModelError(
        f"camera {name!r}: expected a preset ({', '.join(CAMERA_PRESETS)}) or a sensor set "
        f"'camera:NAME' or 'csv:PATH'{hint}"
    )


def camera_sensors(model: CameraModel, *, data_dir: Any = None) -> SensorSet:
    """The sensor set of *model*'s colour filter array, checked when the camera is resolved
    (before any sample): exactly three curves (R, G, B of the CFA), finite and non-negative,
    each responding to CIE D65 between 380 and 780 nm. A CSV of two curves, or of curves with
    no visible response, is refused in one line naming it, instead of failing every sample."""
    sensors = get_sensors(model.sensitivities, data_dir=data_dir)
    where = f"camera {model.name!r}: sensor set {model.sensitivities!r}"
    if len(sensors.channels) != 3:
        raise CameraModelError(
            f"{where} has {len(sensors.channels)} curves ({', '.join(sensors.channels)}); "
            "expected three (R, G, B of the colour filter array)"
        )
    wavelengths = np.arange(380.0, 781.0, 5.0)
    curves = np.asarray(sensors.on(wavelengths), float)
    if not np.isfinite(curves).all() or (curves < 0).any():
        raise CameraModelError(f"{where}: expected finite, non-negative sensitivities")
    d65 = get_spectrum("cie:D65").on(wavelengths)
    dead = [c for c, r in zip(sensors.channels, curves @ d65, strict=True) if not r > 0]
    if dead:
        raise CameraModelError(f"{where}: curve {dead[0]!r} has no response to D65 in 380-780 nm")
    return sensors
