"""Spectral intrinsic layers: image, reflectance, shading, specular and residual per band of the
31-band cube (``bands:31@400-700``, 10 nm box bands), written to ``spectral.exr``.

A K-band diagonal pass multiplies channel by channel along each path, so for a Lambertian
surface ``cube_k = ρ_k · W_k`` holds per band (Eq. 1 of :mod:`spectrinsic.gt_export.layers.irradiance`),
with ``ρ_k = ∫ρ B_k dλ / ∫B_k dλ`` the material's spectrum integrated over band k and ``W_k``
the white-surface radiance (``E_k / π``). The layers are

* ``reflectance_bands``: ``ρ_k`` coverage-weighted over the pixel, the values the renderer
  gave each material (dimensionless; metals 0, as in ``reflectance``);
* ``shading_bands``: ``W_k``, the band radiance a perfect white surface would reflect
  (render units; OIDN-denoised when the sample is, by the band-share scheme of
  :mod:`spectrinsic.gt_export.layers.denoise`);
* ``specular_bands`` (glossy scenes): the raw band channels of the first hits'
  non-diffuse lobes;
* ``image_bands``: the image of the identity, the raw cube, or (denoised samples) the cube
  rebuilt from the denoised ``W`` plus the raw specular, with the raw cube kept as
  ``image_bands_raw``;
* ``residual_bands = image_bands − reflectance_bands ∘ shading_bands −
  specular_bands``.

Per band the product is exact up to float32 rounding where surfaces cover at least
:data:`~spectrinsic.gt_export.layers.irradiance.COVERAGE_MIN` of a pixel and the band albedo is above
:data:`~spectrinsic.gt_export.layers.irradiance.ALBEDO_FLOOR`; the residual holds the rest (the
background and silhouette fringes, pixels a metal shares with a diffuse surface, black
bands). The RGB identity is not exact in
this sense: a 3-channel product cannot represent a spectral one, so its residual holds the
spectral non-commutativity (:func:`residual_share` measures both).

Storage: float32. Stored as half floats, the per-band identity of a denoised room (24², two
lights) was off by 7.0e-4 of the image's largest value (2.6e-4 per value at the median),
against 2e-15 in float32: far above the 1e-5 the layers promise.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...spectra import COLORIMETRIC_WAVELENGTHS, get_sensors, get_spectrum, responses
from . import irradiance as irr
from .gloss import SPECULAR, SPECULAR_BANDS, specular_raw
from .intrinsics import white_radiance
from .records import Layer, SampleInputs, cube_sensor_name, make_layer

__all__ = [
    "SPECTRAL_MODE",
    "SPECTRAL_GROUP",
    "spectral_layers",
    "spectral_identity",
    "residual_share",
    "residual_shares",
    "rgb_residual_share",
    "LIGHT_FAMILIES",
    "light_family",
    "residual_rows",
    "residual_summary",
    "gamut_key",
    "bands_to_rgb",
    "band_image",
]

#: The render mode whose raw cube the spectral layers come from.
SPECTRAL_MODE = "bands31"
#: File stem of the spectral layers (``spectral.exr``).
SPECTRAL_GROUP = "spectral"

_UNITS_BANDS = "band radiance ∫ L B_k dλ (render units) for the bands of {bands!r}"


def _band_white(
    s: SampleInputs, coverage: np.ndarray, w_raw: irr.WhiteRadiance, w: irr.WhiteRadiance
) -> tuple[irr.WhiteRadiance, irr.WhiteRadiance]:
    """``W`` of the 31-band cube, raw and as used (the reference's own when it is the cube;
    else computed from the cube and not denoised)."""
    if s.ref == SPECTRAL_MODE:
        return w_raw, w
    band = white_radiance(dataclasses.replace(s, ref=SPECTRAL_MODE), coverage)
    return band, band


def band_image(
    albedo: np.ndarray,
    shading: np.ndarray,
    valid: np.ndarray,
    cube: np.ndarray,
    specular: np.ndarray | None,
) -> np.ndarray:
    """``image_bands`` of a denoised sample: ``albedo ∘ shading`` (Eq. 1 of
    :mod:`~spectrinsic.gt_export.layers.irradiance`) where *valid*, the cube's diffuse part
    elsewhere, plus the raw *specular*; float64 ``(H, W, K)``. One formula for the writer and
    for the readers that rebuild the layer from its stored factors
    (:mod:`~spectrinsic.gt_export.sample.layer_storage`)."""
    cube = np.asarray(cube, np.float64)
    diffuse = cube if specular is None else cube - specular
    image = np.where(np.asarray(valid, bool)[..., None], albedo * shading, diffuse)
    return image if specular is None else image + specular


def _image(w: irr.WhiteRadiance, cube: np.ndarray, specular: np.ndarray | None) -> np.ndarray:
    """The cube rebuilt from a denoised ``W`` (plus the raw specular) where it is valid, from
    ``W`` as stored (float32, ``shading_bands``), so readers rebuild it bit for bit."""
    return band_image(
        w.albedo, w.bands.astype(np.float32).astype(np.float64), w.valid, cube, specular
    )


def spectral_layers(
    s: SampleInputs,
    coverage: np.ndarray,
    w_raw: irr.WhiteRadiance,
    w: irr.WhiteRadiance,
    *,
    denoised: bool,
) -> list[Layer]:
    """The ``*_bands`` layers of one sample (module notes); :class:`DatasetError` without
    the 31-band cube."""
    if SPECTRAL_MODE not in s.result.raw:
        raise DatasetError(
            "spectral layers need the 31-band cube (render mode 'bands31'); render it or "
            "leave out --spectral-layers"
        )
    bands = cube_sensor_name(s.result)
    channels = get_sensors(bands, data_dir=s.data_dir).channels
    units = _UNITS_BANDS.format(bands=bands)
    raw_w, used_w = _band_white(s, coverage, w_raw, w)
    cube = np.asarray(s.result.raw[SPECTRAL_MODE], np.float64)
    specular = specular_raw(dataclasses.replace(s, ref=SPECTRAL_MODE))
    rebuilt = denoised and used_w is not raw_w
    image = _image(used_w, cube, specular) if rebuilt else cube

    def layer(name: str, data: np.ndarray, what: str, nonnegative: bool = False) -> Layer:
        return make_layer(name, data, channels, what, SPECTRAL_GROUP, nonnegative=nonnegative)

    refl = raw_w.albedo
    out = [
        layer(
            "image_bands",
            image,
            units
            + (
                "; rebuilt as band reflectance × denoised shading_bands (+ specular) where "
                "surfaces cover the pixel, the raw cube elsewhere"
                if rebuilt
                else "; the rendered cube"
            ),
        ),
        layer(
            "reflectance_bands",
            refl,
            "dimensionless band reflectance ∫ρ B_k dλ / ∫B_k dλ, box-filtered by pixel "
            "coverage (0 for background and metals)",
            nonnegative=True,
        ),
        layer(
            "shading_bands",
            used_w.bands,
            "white-surface band radiance W_k = E_k/π (render units), the band light a perfect "
            "white would reflect"
            + ("; OIDN-denoised" if rebuilt else "")
            + "; 0 where surfaces cover less than half the pixel",
        ),
    ]
    if rebuilt:
        out.append(layer("image_bands_raw", cube, units + "; the rendered cube", True))
    if specular is not None:
        out.append(layer(SPECULAR_BANDS, specular, units + "; non-diffuse lobes"))
    out.append(
        layer(
            "residual_bands",
            irr.residual(image, refl, used_w.bands, specular),
            "image_bands − reflectance_bands ∘ shading_bands [− specular_bands] "
            "(render units): the background, silhouette fringes, pixels a metal shares with "
            "a diffuse surface, and bands a surface does not reflect",
        )
    )
    return out


def spectral_identity(layers: Any) -> dict[str, str] | None:
    """The per-band identity's layer names, or ``None`` without spectral layers."""
    if "shading_bands" not in layers:
        return None
    out = {
        "image": "image_bands",
        "reflectance": "reflectance_bands",
        "shading": "shading_bands",
        "residual": "residual_bands",
    }
    return out | ({SPECULAR: SPECULAR_BANDS} if SPECULAR_BANDS in layers else {})


def residual_share(image: np.ndarray, residual: np.ndarray, mask: np.ndarray) -> float:
    """``Σ|residual| / Σ|image|`` over the pixels of *mask* and every channel (0 if dark).

    >>> residual_share(np.ones((1, 2, 3)), np.full((1, 2, 3), 0.25), np.ones((1, 2), bool))
    0.25
    """
    m = np.asarray(mask, bool)
    den = float(np.abs(np.asarray(image, np.float64)[m]).sum())
    num = float(np.abs(np.asarray(residual, np.float64)[m]).sum())
    return num / den if den > 0 else 0.0


def residual_shares(identities: list[dict[str, str]], layers: Any, mask: np.ndarray) -> dict:
    """``{identity image layer: residual share}`` of every identity (``meta.json``'s
    ``residual_share``): ``image``/``image_denoised`` is the RGB share, ``image_bands`` the
    per-band one."""
    return {
        ident["image"]: residual_share(
            layers[ident["image"]].data, layers[ident["residual"]].data, mask
        )
        for ident in identities
    }


def rgb_residual_share(meta: Any) -> float | None:
    """The RGB residual share a ``meta.json`` records (of ``image_denoised`` when denoised,
    else of ``image``), or ``None`` if it records none.

    >>> rgb_residual_share({"residual_share": {"image": 0.1, "image_bands": 0.001}})
    0.1
    """
    shares = meta.get("residual_share") if isinstance(meta, Mapping) else None
    if not isinstance(shares, Mapping):
        return None
    value = shares.get("image_denoised", shares.get("image"))
    return float(value) if isinstance(value, (int, float)) else None


#: Light families from the most to the least saturated; a sample's family is the first that
#: one of its lights belongs to (:func:`light_family`).
LIGHT_FAMILIES: tuple[str, ...] = (
    "narrow-led",
    "rgb-led",
    "filtered",
    "fluorescent",
    "white-led",
    "daylight",
    "planckian",
    "d65",
    "other",
)


def _family_of(spectrum: str) -> str:
    kind, _, key = spectrum.partition(":")
    if kind == "led" or (kind == "cie" and key.startswith("LED-RGB")):
        return "rgb-led" if "+" in key or kind == "cie" else "narrow-led"
    if kind == "filtered":
        return "filtered"
    if kind == "cie" and key.startswith("FL") or kind == "sfu":
        return "fluorescent"
    if kind == "cie" and key.startswith("LED"):
        return "white-led"
    if kind == "cie" and key == "D65":
        return "d65"
    if kind == "daylight" or (kind == "cie" and key.startswith("D")):
        return "daylight"
    return "planckian" if kind in ("planck", "blackbody") or key == "A" else "other"


def light_family(spectra: Any) -> str:
    """The family of a set of light spectrum names: that of its most saturated light
    (:data:`LIGHT_FAMILIES` order).

    >>> light_family(["cie:D65", "led:540/31"]), light_family(["planck:2800K"])
    ('narrow-led', 'planckian')
    """
    found = {_family_of(str(s)) for s in spectra}
    return next((f for f in LIGHT_FAMILIES if f in found), "other")


def _figures(values: list[float]) -> dict[str, float]:
    v = np.asarray(values, np.float64)
    return {
        "median": float(np.median(v)),
        "p95": float(np.percentile(v, 95)),
        "max": float(v.max()),
    }


_ROW_KEYS = ("rgb", "spectral", "clipped_pixels", "out_of_gamut_share")


def gamut_key(meta: Any) -> str:
    """The name of a sample's share of lit pixels whose working-space shading has a negative
    channel: ``"clipped_pixels"`` where the space clips it into the residual (``srgb``, and
    samples written before the working space was recorded), else ``"out_of_gamut_share"``
    (ACEScg, Rec.2020 keep it in the shading: nothing is clipped).

    >>> gamut_key({"working_space": {"name": "acescg", "shading_clipped": False}})
    'out_of_gamut_share'
    >>> gamut_key({})
    'clipped_pixels'
    """
    record = meta.get("working_space") if isinstance(meta, Mapping) else None
    clipped = record.get("shading_clipped", True) if isinstance(record, Mapping) else True
    return "clipped_pixels" if clipped else "out_of_gamut_share"


def residual_rows(metas: Any) -> dict[str, dict[str, list[float]]]:
    """Per light family (:func:`light_family` of each sample's lights): the samples' RGB
    residual shares (``"rgb"``), per-band residual shares where written (``"spectral"``) and
    shares of lit pixels whose shading has a negative channel in the working space
    (:func:`gamut_key`: ``"clipped_pixels"`` in sRGB, ``"out_of_gamut_share"`` where nothing is
    clipped), fractions in sample order. *metas* are parsed ``meta.json`` objects; samples
    without a residual share are skipped.
    """
    rows: dict[str, dict[str, list[float]]] = {}
    for meta in metas:
        rgb = rgb_residual_share(meta)
        if rgb is None:
            continue
        family = light_family(li.get("spectrum", "") for li in meta.get("lights", []))
        row = rows.setdefault(family, {k: [] for k in _ROW_KEYS})
        row["rgb"].append(rgb)
        spectral = (meta.get("residual_share") or {}).get("image_bands")
        gamut = (meta.get("shading_clipping") or {}).get("pixels")
        for key, value in (("spectral", spectral), (gamut_key(meta), gamut)):
            if isinstance(value, (int, float)):
                row[key].append(float(value))
    return rows


def residual_summary(metas: Any) -> dict[str, Any]:
    """Per light family (:func:`light_family` of each sample's lights) and ``"all"``: the
    samples' RGB residual share, per-band residual share (where written) and the share of lit
    pixels whose shading has a negative channel in the working space (``clipped_pixels`` or
    ``out_of_gamut_share``, :func:`gamut_key`), each as median / p95 / max over samples
    (fractions).
    *metas* are parsed ``meta.json`` objects; samples without a residual share are skipped.

    >>> m = {"lights": [{"spectrum": "cie:D65"}], "residual_share": {"image": 0.01},
    ...      "shading_clipping": {"pixels": 0.0}}
    >>> residual_summary([m])["d65"]["rgb"]["median"]
    0.01
    """
    rows = residual_rows(metas)
    if rows:
        rows["all"] = {k: [v for row in rows.values() for v in row[k]] for k in _ROW_KEYS}
    return {
        family: {"samples": len(row["rgb"])} | {k: _figures(v) for k, v in row.items() if v}
        for family, row in sorted(rows.items())
    }


def bands_to_rgb(
    layers: Mapping[str, np.ndarray],
    to_xyz: np.ndarray,
    matrix: np.ndarray,
    *,
    bands: str = "bands:31@400-700",
    clip: bool = False,
) -> dict[str, np.ndarray]:
    """RGB intrinsic layers in the space of *matrix* (XYZ -> RGB) from a sample's band layers:
    ``image = M X cube``, ``reflectance = M X (ρ ∘ D) / Y_D`` (under D65, D its band values),
    ``shading = M X W / white`` with ``white = M X D / Y_D`` (clipped at 0 if *clip*),
    ``specular``, and ``residual = image − reflectance ∘ shading − specular``; X = *to_xyz*,
    the cube's raw -> XYZ matrix (``meta.json["render"]["to_xyz"]["bands31"]``). The
    reflectance is integrated from the bands (within 0.5 % of the 1 nm one). Render units.
    """
    wl = COLORIMETRIC_WAVELENGTHS
    d65 = responses(get_spectrum("cie:D65").on(wl), get_sensors(bands).on(wl), wl)
    x = np.asarray(matrix, np.float64) @ np.asarray(to_xyz, np.float64)
    y_d = float((np.asarray(to_xyz, np.float64) @ d65)[1])
    white = x @ d65 / y_d

    def rgb(name: str) -> np.ndarray:
        return np.einsum("hwk,ck->hwc", np.asarray(layers[name], np.float64), x)

    out = {
        "image": rgb("image_bands"),
        "reflectance": np.einsum(
            "hwk,ck->hwc", np.asarray(layers["reflectance_bands"], np.float64) * d65, x
        )
        / y_d,
        "shading": rgb("shading_bands") / white,
    }
    if clip:
        out["shading"] = np.clip(out["shading"], 0.0, None)
    rest = out["image"] - out["reflectance"] * out["shading"]
    if SPECULAR_BANDS in layers:
        out[SPECULAR] = rgb(SPECULAR_BANDS)
        rest = rest - out[SPECULAR]
    out["residual"] = rest
    return out
