"""Reflectance spectra: Munsell chips, the ColorChecker, the SFU set and flat greys.

All reflectances are fractions in [0, 1] of incident light, on their native grids (nm).
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Mapping
from types import MappingProxyType

import numpy as np

from ..errors import SpectrumNotFoundError, did_you_mean
from . import io
from .grid import wavelength_grid
from .records import Spectrum

__all__ = [
    "mix",
    "munsell",
    "munsell_names",
    "colorchecker",
    "colorchecker_names",
    "sfu_reflectance",
    "sfu_reflectance_names",
    "flat",
]

MUNSELL_SOURCE = (
    "1269 matte Munsell chips, University of Eastern Finland (Parkkinen et al. 1989), "
    "via luxpy's Munsell1269.dat"
)
SFU_SOURCE = "Barnard, Martin, Funt & Coath, Color Res. Appl. 27(3):147-151, 2002"
_NOTATION = re.compile(
    r"^\s*(\d+(?:\.\d+)?)\s*([A-Z]{1,2})\s+(\d+(?:\.\d+)?)\s*/\s*(\d+(?:\.\d+)?)\s*$"
)


def _fmt(x: float) -> str:
    return f"{x:g}"


def _canonical(hue: str, value: float, chroma: float) -> str:
    m = re.match(r"^(\d+(?:\.\d+)?)([A-Z]{1,2})$", hue)
    hue = f"{_fmt(float(m.group(1)))}{m.group(2)}" if m else hue
    return f"{hue} {_fmt(value)}/{_fmt(chroma)}"


@functools.lru_cache(maxsize=1)
def _munsell_index() -> Mapping[str, int]:
    """Canonical notation -> row of the Munsell table; read-only, as it is cached."""
    _, notations = io.read_munsell()
    return MappingProxyType({_canonical(*n): i for i, n in enumerate(notations)})


def munsell_names() -> list[str]:
    """Canonical notations of the 1269 chips, e.g. ``"5R 4/14"``, in file order."""
    return list(_munsell_index())


def munsell(key: str) -> Spectrum:
    """A Munsell chip by notation (``"5R 4/14"``, ``"5.0R 4.0/14.0"``) or index (``"#12"``)."""
    table, notations = io.read_munsell()
    key = key.strip()
    if key.startswith("#"):
        try:
            idx = int(key[1:])
        except ValueError:
            idx = -1
        if not 0 <= idx < table.values.shape[0]:
            raise SpectrumNotFoundError(
                f"Munsell index {key!r} out of range; expected '#0' to '#{table.values.shape[0] - 1}'"
            )
    else:
        m = _NOTATION.match(key.upper())
        canonical = (
            _canonical(m.group(1) + m.group(2), float(m.group(3)), float(m.group(4))) if m else key
        )
        index = _munsell_index()
        if canonical not in index:
            raise SpectrumNotFoundError(
                f"unknown Munsell chip {key!r}; expected a notation like '5R 4/14' among the 1269 "
                f"matte chips" + did_you_mean(canonical, index, n=4)
            )
        idx = index[canonical]
    name = "munsell:" + _canonical(*notations[idx])
    return Spectrum(name, "reflectance", table.wavelengths, table.values[idx], MUNSELL_SOURCE)


def colorchecker_names() -> list[str]:
    """Patch names of colour-science's BabelColor average ColorChecker."""
    import colour

    return list(colour.SDS_COLOURCHECKERS["BabelColor Average"])


def colorchecker(key: str) -> Spectrum:
    """A ColorChecker patch (BabelColor average, via colour-science), e.g. ``"dark skin"``."""
    import colour

    sds = colour.SDS_COLOURCHECKERS["BabelColor Average"]
    if key not in sds:
        raise SpectrumNotFoundError(f"unknown ColorChecker patch {key!r}" + did_you_mean(key, sds))
    sd = sds[key]
    return Spectrum(
        f"colorchecker:{key}",
        "reflectance",
        np.asarray(sd.wavelengths, float),
        np.asarray(sd.values, float),
        "BabelColor average ColorChecker (colour-science)",
    )


def sfu_reflectance_names(data_dir: str | None = None) -> list[str]:
    """``group/index`` keys of the 1995 SFU reflectances, e.g. ``"munsell/17"``."""
    _, keys = io.read_sfu_reflectances(data_dir)
    return [f"{g}/{i}" for g, i in keys]


def sfu_reflectance(key: str, data_dir: str | None = None) -> Spectrum:
    """An SFU reflectance by ``group/index`` (1-based index within the group).

    Dupont, Krinov and Vrhel spectra are zero-filled outside their measured range; those zeros
    are treated as missing, so the returned spectrum covers only the measured range and
    :meth:`Spectrum.on` holds its edge values beyond it.
    """
    table, keys = io.read_sfu_reflectances(data_dir)
    names = [f"{g}/{i}" for g, i in keys]
    try:
        col = names.index(key.strip())
    except ValueError:
        raise SpectrumNotFoundError(
            f"unknown SFU reflectance {key!r}; expected 'group/index' with groups "
            f"{sorted({g for g, _ in keys})}" + did_you_mean(key, names)
        ) from None
    values = table.values[col]
    nz = np.flatnonzero(values > 0)
    lo, hi = (int(nz[0]), int(nz[-1]) + 1) if nz.size else (0, values.size)
    return Spectrum(
        f"sfu:{key.strip()}", "reflectance", table.wavelengths[lo:hi], values[lo:hi], SFU_SOURCE
    )


def flat(key: str) -> Spectrum:
    """A spectrally flat (neutral) reflectance, e.g. ``"0.5"``; value in [0, 1]."""
    try:
        value = float(key)
    except ValueError:
        value = -1.0
    if not 0.0 <= value <= 1.0:
        raise SpectrumNotFoundError(f"flat reflectance {key!r}: expected a number in [0, 1]")
    wl = wavelength_grid(360.0, 830.0, 470.0)
    return Spectrum(f"flat:{value:g}", "reflectance", wl, np.full(wl.size, value), "constant")


def mix(key: str, resolve: Callable[[str], Spectrum]) -> Spectrum:
    """A convex combination of reflectances, e.g. ``"0.3*munsell:5R 4/14+0.7*munsell:5B 6/8"``:
    ``ρ(λ) = Σ w_i ρ_i(λ)`` with ``w_i >= 0`` and ``Σ w_i <= 1``, so it stays in [0, 1]
    (spectral textures: a basis of reflectances mixed by per-texel weights). Sampled on the
    first spectrum's wavelengths; *resolve* looks each name up in the registry.
    """
    terms = []
    for term in key.split("+"):
        weight, sep, name = term.partition("*")
        try:
            w = float(weight) if sep and name.strip() else -1.0
        except ValueError:
            w = -1.0
        if not 0.0 <= w <= 1.0:
            raise SpectrumNotFoundError(
                f"mixed reflectance {key!r}: expected WEIGHT*NAME+..., e.g. "
                "'0.3*munsell:5R 4/14+0.7*munsell:5B 6/8'"
            )
        terms.append((w, resolve(name.strip())))
    if sum(w for w, _ in terms) > 1.0 + 1e-9 or any(sp.kind != "reflectance" for _, sp in terms):
        raise SpectrumNotFoundError(
            f"mixed reflectance {key!r}: expected reflectances with weights summing to <= 1"
        )
    wl = np.asarray(terms[0][1].wavelengths, float)
    values = np.clip(sum(w * sp.on(wl) for w, sp in terms), 0.0, 1.0)  # clip: float round-off only
    canonical = "+".join(f"{w:g}*{sp.name}" for w, sp in terms)
    return Spectrum(
        f"mix:{canonical}", "reflectance", wl, values, "convex combination of reflectances"
    )
