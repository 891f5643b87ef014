"""How far a dataset's colours spread: light chromaticities and material chroma.

Pure functions of spectrum names and chromaticities, so they measure a built dataset
(``meta.json``) and a set of scene descriptions alike, without rendering:

* lights: the area of the convex hull of their CIE 1931 xy, the xy distance from D65, |Duv|
  (Ohno 2013, CIE 1960 uv, :func:`~spectrinsic.spectra.xy_to_duv`), and per two-light sample
  the largest xy distance between its lights;
* materials: CIELAB chroma C*ab of each reflectance under D65 (CIE 1931 2°, colour-science);
* scenes: the fraction of objects painted with a spatially varying pattern, and the fraction
  of views framed (object coverage >= :data:`FRAMED`).
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ...scenes.material_labels import label_spectrum
from ...spectra import get_sensors, get_spectrum, responses, xy_to_duv, xyz_to_xy

__all__ = [
    "shown",
    "D65_XY",
    "FRAMED",
    "TINTED_DUV",
    "light_xy",
    "material_chroma",
    "recorded_chromas",
    "hull_area",
    "spread_summary",
]

#: CIE 1931 xy of D65 (CIE 015:2018).
D65_XY = (0.31271, 0.32902)
#: |Duv| from which a light reads as tinted rather than as a white of another temperature.
TINTED_DUV = 0.02
#: Object coverage from which a view counts as framed (as the ``rooms`` generator asks).
FRAMED = 0.3


@functools.lru_cache(maxsize=8192)
def light_xy(name: str, data_dir: str | None = None) -> tuple[float, float]:
    """CIE 1931 xy of illuminant *name* (2° observer)."""
    cmf = get_sensors("cie1931")
    x, y = xyz_to_xy(
        responses(
            get_spectrum(name, data_dir=data_dir).on(cmf.wavelengths), cmf.curves, cmf.wavelengths
        )
    )
    return float(x), float(y)


@functools.lru_cache(maxsize=8192)
def material_chroma(name: str, data_dir: str | None = None) -> float:
    """CIELAB chroma C*ab of reflectance *name* under D65 (white: the perfect diffuser)."""
    import colour

    cmf = get_sensors("cie1931")
    d65 = get_spectrum("cie:D65").on(cmf.wavelengths)
    xyz = responses(
        get_spectrum(name, data_dir=data_dir).on(cmf.wavelengths) * d65, cmf.curves, cmf.wavelengths
    )
    white = responses(d65, cmf.curves, cmf.wavelengths)
    lab = colour.XYZ_to_Lab(xyz / white[1], colour.XYZ_to_xy(white / white[1]))
    return float(np.hypot(lab[1], lab[2]))


def recorded_chromas(names: Any) -> list[float]:
    """:func:`material_chroma` of each recorded material label in *names*, leaving out ``csv:``
    spectra named relative to their scene file's folder (a sample records no absolute path,
    and a dataset does not know where its scene files lie): the card's chroma statistics and
    plot are over the other materials."""
    out = []
    for name in names:
        spectrum = label_spectrum(name)
        if spectrum[:4].lower() == "csv:" and not Path(spectrum[4:].strip()).is_absolute():
            continue
        out.append(material_chroma(spectrum))
    return out


def hull_area(points: np.ndarray) -> float:
    """Area of the convex hull of ``(N, 2)`` points (0 for fewer than 3), by the monotone chain."""
    pts = sorted({(float(x), float(y)) for x, y in np.asarray(points, float).reshape(-1, 2)})
    if len(pts) < 3:
        return 0.0

    def half(seq: list[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for p in seq:
            while (
                len(out) >= 2
                and (
                    (out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                    - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])
                )
                <= 0
            ):
                out.pop()
            out.append(p)
        return out

    ring = half(pts)[:-1] + half(pts[::-1])[:-1]
    return 0.5 * abs(
        sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(ring, ring[1:] + ring[:1], strict=True))
    )


def shown(value: float, fmt: str) -> str:
    """A figure *value* formatted with *fmt*, or ``n/a`` where the set had nothing to measure."""
    return "n/a" if math.isnan(value) else format(value, fmt)


def spread_summary(samples: Sequence[Mapping[str, Any]]) -> dict[str, float]:
    """Figures of a set of samples, each ``{"lights": [xy...], "materials": [names],
    "patterned": k, "objects": n, "coverage": f or None}`` (lights as CIE 1931 xy pairs).

    Returns
    -------
    dict
        ``xy_hull_area``, ``d65_distance_median``/``_max`` (xy), ``tinted_fraction`` (|Duv| >=
        TINTED_DUV among non-D65 lights), ``pair_distance_min``/``_median`` (largest xy distance
        within each sample of >= 2 distinct lights), ``chroma_median``/``_p90`` (C*ab),
        ``patterned_fraction`` and ``textured_fraction`` (spectral textures) of objects,
        ``framed_fraction`` of views with a coverage.
    """
    xy = np.array([p for s in samples for p in s["lights"]], float).reshape(-1, 2)
    d65 = np.linalg.norm(xy - np.array(D65_XY), axis=1)
    coloured = xy[d65 > 0.005]
    duv = np.abs(xy_to_duv(coloured)) if len(coloured) else np.zeros(0)
    pairs = [
        max(math.dist(a, b) for a, b in itertools.combinations(pts, 2))
        for s in samples
        if len(pts := {tuple(p) for p in s["lights"]}) >= 2
    ]
    chroma = np.array(recorded_chromas(n for s in samples for n in s["materials"]), float)
    objects = sum(int(s.get("objects", 0)) for s in samples)
    covs = [float(s["coverage"]) for s in samples if s.get("coverage") is not None]

    def stat(values: Any, f: Any) -> float:
        return float(f(values)) if len(values) else float("nan")

    return {
        "samples": float(len(samples)),
        "xy_hull_area": hull_area(xy),
        "d65_distance_median": stat(d65, np.median),
        "d65_distance_max": stat(d65, np.max),
        "tinted_fraction": stat(duv >= TINTED_DUV, np.mean),
        "pair_distance_min": stat(pairs, np.min),
        "pair_distance_median": stat(pairs, np.median),
        "chroma_median": stat(chroma, np.median),
        "chroma_p90": stat(chroma, lambda v: np.percentile(v, 90)),
        "patterned_fraction": sum(int(s.get("patterned", 0)) for s in samples) / objects
        if objects
        else float("nan"),
        "textured_fraction": sum(int(s.get("textured", 0)) for s in samples) / objects
        if objects
        else float("nan"),
        "framed_fraction": stat(np.array(covs) >= FRAMED, np.mean),
    }
