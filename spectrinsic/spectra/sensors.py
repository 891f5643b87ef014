"""Sensor sets: the CIE 1931 observer, linear sRGB, Gaussian and box bands, cameras, user files.

Sensitivities are relative, per nm. Gaussian and box sensors are synthetic, as in thesis
section 5.2.3 ("Gaussian shaped sensors which are equally spaced over the visible spectrum").
"""

from __future__ import annotations

import functools
import re

import numpy as np

from ..data_dir import resolve_data_dir
from ..errors import SpectrumNotFoundError, did_you_mean
from . import io
from .colourspace import srgb_matrices
from .grid import wavelength_grid
from .records import SensorSet

__all__ = [
    "cie1931",
    "srgb",
    "gaussian_sensors",
    "gaussian",
    "box_bands",
    "bands",
    "camera",
    "camera_names",
    "user_csv",
    "CAMERA_TABLES",
]

#: Camera tables in a data directory: relative path and citation.
CAMERA_TABLES: dict[str, tuple[str, str]] = {
    "jiang2013": (
        "camera_jiang2013_camspec/camspec_jiang2013_28cameras.csv",
        "Jiang, Liu, Gu & Süsstrunk, WACV 2013 (CC BY-NC-SA 4.0)",
    ),
    "ie2024": (
        "camera_imageengineering_2024/ie2024_98cameras.csv",
        "Image Engineering 2024 camera sensitivities (secondary, licence unknown)",
    ),
}
_SPEC = re.compile(r"^\s*(\d+)\s*(?:@\s*(\d+(?:\.\d+)?)\s*-\s*(\d+(?:\.\d+)?))?\s*$")


@functools.lru_cache(maxsize=1)
def cie1931() -> SensorSet:
    """CIE 1931 2° colour-matching functions x̄, ȳ, z̄ (360–830 nm at 1 nm)."""
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wavelengths = np.array(cmfs.wavelengths, dtype=float)
    curves = np.asarray(cmfs.values, float).T.copy()
    for array in (wavelengths, curves):
        array.flags.writeable = False  # cached: shared by every caller
    return SensorSet(
        "cie1931",
        ("X", "Y", "Z"),
        wavelengths,
        curves,
        "CIE 1931 2 degree observer (colour-science)",
    )


@functools.lru_cache(maxsize=1)
def srgb() -> SensorSet:
    """Linear sRGB sensitivities ``M_XYZ→sRGB · [x̄ ȳ z̄]`` (IEC 61966-2-1); negative lobes included.

    Responses to these curves are linear sRGB values, identical to converting XYZ responses with
    :func:`spectrinsic.spectra.xyz_to_linear_srgb`.
    """
    cmf = cie1931()
    # einsum's own loop, not BLAS: the curves' bits must not change with the CPU kernel.
    curves = np.einsum("kj,jw->kw", srgb_matrices()[0], cmf.curves)
    curves.flags.writeable = False
    return SensorSet(
        "srgb",
        ("R", "G", "B"),
        cmf.wavelengths,
        curves,
        "linear sRGB from the CIE 1931 observer (IEC 61966-2-1)",
    )


def _range(key: str, what: str) -> tuple[int, float, float]:
    m = _SPEC.match(key)
    if not m:
        raise SpectrumNotFoundError(
            f"{what} {key!r}: expected 'N' or 'N@START-END' (nm), e.g. '6@400-700'"
        )
    n = int(m.group(1))
    lo = float(m.group(2)) if m.group(2) else 400.0
    hi = float(m.group(3)) if m.group(3) else 700.0
    if n < 1 or not hi > lo:
        raise SpectrumNotFoundError(f"{what} {key!r}: expected N >= 1 sensors and END > START")
    return n, lo, hi


def gaussian_sensors(
    n: int,
    start: float = 400.0,
    end: float = 700.0,
    *,
    sigma: float | None = None,
    wavelengths: np.ndarray | None = None,
) -> SensorSet:
    """*n* Gaussian sensors centred in *n* equal bins of [start, end] nm.

    Defaults reproduce thesis Table 5.2 (ARCHITECTURE.md): n = 3 gives centres 450/550/650 nm;
    σ = bin width / 4; each curve normalised to unit area on its grid (``Σ S Δλ = 1``).
    Curves are evaluated on *wavelengths* (default 360–830 nm at 1 nm).
    """
    width = (end - start) / n
    centres = start + width * (np.arange(n) + 0.5)
    sig = width / 4.0 if sigma is None else float(sigma)
    wl = (
        wavelength_grid(360.0, 830.0, 1.0)
        if wavelengths is None
        else np.asarray(wavelengths, float)
    )
    curves = np.exp(-0.5 * ((wl[None, :] - centres[:, None]) / sig) ** 2)
    curves /= (curves * np.gradient(wl)[None, :]).sum(axis=1, keepdims=True)
    name = f"gaussian:{n}@{start:g}-{end:g}"
    return SensorSet(
        name, tuple(f"G{c:.0f}" for c in centres), wl, curves, "synthetic (thesis 5.2.3)"
    )


def gaussian(key: str) -> SensorSet:
    """Registry loader: ``"6"`` or ``"6@400-700"``."""
    n, lo, hi = _range(key, "Gaussian sensors")
    return gaussian_sensors(n, lo, hi)


def box_bands(n: int, start: float = 400.0, end: float = 700.0) -> SensorSet:
    """*n* contiguous box bands centred on an even grid from *start* to *end* nm (centres included).

    ``"bands:31@400-700"`` gives 10 nm bands centred at 400, 410, ..., 700 nm; the bands sum to 1
    over their joint support, so a band cube integrates back to any sensor by a weighted sum.
    """
    centres = np.linspace(start, end, n) if n > 1 else np.array([(start + end) / 2])
    width = (end - start) / (n - 1) if n > 1 else end - start
    wl = wavelength_grid(360.0, 830.0, 0.5)
    dist = np.abs(wl[None, :] - centres[:, None])
    curves = np.where(dist < width / 2, 1.0, np.where(np.isclose(dist, width / 2), 0.5, 0.0))
    name = f"bands:{n}@{start:g}-{end:g}"
    return SensorSet(name, tuple(f"B{c:g}" for c in centres), wl, curves, "synthetic box bands")


def bands(key: str) -> SensorSet:
    """Registry loader: ``"31"`` or ``"31@400-700"``."""
    n, lo, hi = _range(key, "box bands")
    return box_bands(n, lo, hi)


def _builtin_cameras() -> dict[str, tuple[np.ndarray, np.ndarray, str]]:
    import colour

    out = {}
    for name, msds in colour.characterisation.MSDS_CAMERA_SENSITIVITIES.items():
        out[name] = (
            np.asarray(msds.wavelengths, float),
            np.asarray(msds.values, float).T.copy(),
            "Darrodi et al. 2015 (NPL) via colour-science",
        )
    return out


def _all_cameras(data_dir: str | None) -> dict[str, tuple[np.ndarray, np.ndarray, str]]:
    cams = _builtin_cameras()
    root = resolve_data_dir(data_dir)
    if root is not None:
        for table, (relative, source) in CAMERA_TABLES.items():
            if (root / relative).is_file():
                for name, (wl, curves) in io.read_camera_table(str(root), relative).items():
                    key = name if table == "jiang2013" else f"{name} [IE]"
                    cams.setdefault(key, (wl, curves, source))
    return cams


def camera_names(data_dir: str | None = None) -> list[str]:
    """Cameras available: colour-science's two, plus those of a configured data directory."""
    return list(_all_cameras(data_dir))


def camera(key: str, data_dir: str | None = None) -> SensorSet:
    """A camera's R, G, B sensitivities by name, e.g. ``"Nikon 5100 (NPL)"`` or ``"Nikon D50"``."""
    cams = _all_cameras(data_dir)
    if key not in cams:
        hint = (
            "" if data_dir or len(cams) > 2 else " (more cameras with --data-dir/SPECTRINSIC_DATA)"
        )
        raise SpectrumNotFoundError(f"unknown camera {key!r}" + did_you_mean(key, cams) + hint)
    wl, curves, source = cams[key]
    return SensorSet(f"camera:{key}", ("R", "G", "B"), wl, curves, source)


def user_csv(path: str) -> SensorSet:
    """Sensors from a user CSV: ``wavelength_nm`` column, then one column per sensor (>= 0)."""
    table = io.read_user_csv(path, kind="sensitivity")
    return SensorSet(
        f"csv:{path}", table.labels, table.wavelengths, table.values, f"user file {path}"
    )
