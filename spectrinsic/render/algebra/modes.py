"""Render modes and the colour maths each needs: channel values (Eq. 5.2) and the map to XYZ.

A *mode* names a sensor set and how its raw channels become CIE 1931 XYZ:

=========  ====================  =========  ===============================================
mode       sensors               passes     raw channels -> XYZ
=========  ====================  =========  ===============================================
spectral   ``cie1931``           1 spectral identity (``specfilm`` bands are x̄, ȳ, z̄)
rgb3       ``cie1931``           1 RGB      identity (the usual 3-channel graphics render)
gauss3     ``gaussian:3@400-700`` 1 RGB     linear regression, as rgb6 (the thesis' 3 sensors)
rgb6       ``gaussian:6@400-700`` 2 RGB     linear regression (thesis 5.2.3), see
                                            :func:`regression_matrix`
bands31    ``bands:31@400-700``  11 RGB     integration against x̄, ȳ, z̄, see
                                            :func:`integration_matrix`
=========  ====================  =========  ===============================================

``rgb3`` takes the CMFs themselves as diagonal sensors, as the contract asks. Their overlap and
x̄'s blue lobe make it a poor approximation under warm or spiky light: for the chip 5R 5/12
under 2800 K, one bounce, X is 19 % low (``tests/render/test_physics.py``). ``gauss3`` is the
thesis' own 3-sensor set for comparison with ``rgb6``.

A *diagonal* render of K sensors gives material m the channel values ``∫ρ_m S_k dλ / ∫S_k dλ``
and light l the values ``power_l ∫L_l S_k dλ`` (Eq. 5.2 with 5.4 normalised, 5.5), so a flat
reflectance keeps its value and every product of reflectances and a light is in the units of
``specfilm``: ``∫ (radiance) S_k dλ`` with λ in nm. Integrals run on the 1 nm CIE grid
(360–830 nm), where the exact ground truth is integrated too.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ...arrays import Wavelengths
from ...errors import RenderError, SpectralDataError, validate_choice
from ...scenes.model import Material, Scene
from ...spectra import (
    COLORIMETRIC_WAVELENGTHS,
    SensorSet,
    diagonal_values,
    family_values,
    fit_projection,
    get_sensors,
    get_spectrum,
    responses,
)
from ...spectra.conductors import FRESNEL_NODES, fresnel_table

__all__ = [
    "RenderMode",
    "RENDER_MODES",
    "XYZ_SENSORS",
    "get_mode",
    "n_passes",
    "ChannelValues",
    "channel_values",
    "light_spectra",
    "integration_matrix",
    "regression_matrix",
    "to_xyz_matrix",
    "raw_to_xyz",
    "pad_to_passes",
]

#: The output sensors every mode is converted to.
XYZ_SENSORS = "cie1931"


@dataclass(frozen=True)
class RenderMode:
    """One way of rendering colour.

    Attributes
    ----------
    name
        Registry key (``"rgb6"``).
    sensors
        Registry name of the K sensor curves rendered (:func:`spectrinsic.spectra.get_sensors`).
    kind
        ``"spectral"`` (Mitsuba spectral variant with a ``specfilm``) or ``"diagonal"``
        (⌈K/3⌉ passes of an RGB variant).
    to_xyz
        ``"identity"`` (the sensors are x̄, ȳ, z̄), ``"regression"`` (:func:`regression_matrix`)
        or ``"integration"`` (:func:`integration_matrix`).
    description
        One line for ``--help`` and reports.
    """

    name: str
    sensors: str
    kind: Literal["spectral", "diagonal"]
    to_xyz: Literal["identity", "regression", "integration"]
    description: str


RENDER_MODES: dict[str, RenderMode] = {
    m.name: m
    for m in (
        RenderMode(
            "spectral",
            "cie1931",
            "spectral",
            "identity",
            "spectral reference: Mitsuba spectral variant, specfilm with the CIE 1931 CMFs",
        ),
        RenderMode(
            "rgb3",
            "cie1931",
            "diagonal",
            "identity",
            "3-channel diagonal render with the CIE 1931 CMFs as sensors",
        ),
        RenderMode(
            "gauss3",
            "gaussian:3@400-700",
            "diagonal",
            "regression",
            "3 Gaussian sensors (the thesis' Table 5.2 set) in one RGB pass, regressed to XYZ",
        ),
        RenderMode(
            "rgb6",
            "gaussian:6@400-700",
            "diagonal",
            "regression",
            "6 Gaussian sensors in two RGB passes, regressed to XYZ (thesis 5.2.3)",
        ),
        RenderMode(
            "bands31",
            "bands:31@400-700",
            "diagonal",
            "integration",
            "31 box bands of 10 nm in 11 RGB passes, integrated against the CMFs",
        ),
    )
}


def get_mode(name: str) -> RenderMode:
    """The :class:`RenderMode` called *name*; a one-line error with close matches otherwise."""
    return RENDER_MODES[validate_choice(name, RENDER_MODES, "render mode", error=RenderError)]


def n_passes(mode: RenderMode, *, data_dir: str | None = None) -> int:
    """Number of Mitsuba renders one image of *mode* takes (1, or ⌈K/3⌉ for diagonal modes)."""
    if mode.kind == "spectral":
        return 1
    return -(-get_sensors(mode.sensors, data_dir=data_dir).n // 3)


@dataclass(frozen=True, eq=False)
class ChannelValues:
    """Channel values of one diagonal render.

    Attributes
    ----------
    materials
        ``(M, K)`` float64 ``∫ρ_m S_k / ∫S_k`` in [0, 1] for reflectances in [0, 1].
    lights
        ``(L, K)`` float64 ``power_l ∫L_l S_k dλ`` (λ in nm).
    specular
        ``(M, N, K)`` float64 band factors of each material's non-diffuse lobe at N cosines
        (:func:`spectrinsic.spectra.conductors.fresnel_table` for a conductor, 1 otherwise),
        when the scene has glossy materials; ``None`` otherwise.
    transmittance
        ``(M, K)`` float64 band values ``∫T_m S_k / ∫S_k`` of each glass's transmittance, as
        :attr:`materials` of its reflectance (1 for clear glass and every other material),
        when the scene has tinted glass; ``None`` otherwise.
    specular_reflectance
        ``(M, K)`` band values of each glass's reflection tint, as :attr:`transmittance`.
    """

    materials: np.ndarray
    lights: np.ndarray
    specular: np.ndarray | None = None
    transmittance: np.ndarray | None = None
    specular_reflectance: np.ndarray | None = None


def light_spectra(
    scene: Scene,
    wavelengths: Wavelengths = COLORIMETRIC_WAVELENGTHS,
    *,
    data_dir: str | None = None,
) -> np.ndarray:
    """``(L, W)`` emitted spectra of the scene's lights: ``power · L(λ)`` on *wavelengths*."""
    return _stack(
        [
            li.power * get_spectrum(li.spectrum, data_dir=data_dir).on(wavelengths)
            for li in scene.lights
        ],
        wavelengths,
    )


def _stack(rows: list[np.ndarray], wavelengths: Wavelengths) -> np.ndarray:
    """``(N, W)`` spectra from *rows*, ``(0, W)`` for none."""
    return np.stack(rows) if rows else np.zeros((0, np.size(wavelengths)))


def channel_values(
    scene: Scene, sensors: SensorSet, *, data_dir: str | None = None
) -> ChannelValues:
    """Material and light channel values of a diagonal render of *scene* with *sensors*.

    Materials get ``∫ρ S_k dλ / ∫S_k dλ`` (Eq. 5.4 normalised), lights ``power ∫L S_k dλ``
    (Eq. 5.5), integrated on the CIE grid (nm). Their product is the diagonal estimate
    ``p̂_k`` of Eq. 5.2.
    """
    wl = COLORIMETRIC_WAVELENGTHS
    curves = sensors.on(wl)
    rho = _stack([get_spectrum(m.spectrum, data_dir=data_dir).on(wl) for m in scene.materials], wl)
    return ChannelValues(
        materials=diagonal_values(rho, curves, wl),
        lights=responses(light_spectra(scene, data_dir=data_dir), curves, wl),
        specular=_specular(scene, curves, data_dir),
        transmittance=_tint(scene, "transmittance", curves, data_dir),
        specular_reflectance=_tint(scene, "specular_reflectance", curves, data_dir),
    )


def _tint(scene: Scene, key: str, curves: np.ndarray, data_dir: str | None) -> np.ndarray | None:
    """``(M, K)`` band values of every material's glass tint *key* (1 where it has none);
    ``None`` where no material is tinted."""
    if not any(m.tinted for m in scene.materials):
        return None
    wl = COLORIMETRIC_WAVELENGTHS
    spectra = np.stack(
        [get_spectrum(m.tint(key), data_dir=data_dir).on(wl) for m in scene.materials]
    )
    return diagonal_values(spectra, curves, wl)


def _specular(scene: Scene, curves: np.ndarray, data_dir: str | None) -> np.ndarray | None:
    """``(M, N, K)`` band factors of each material's non-diffuse lobe: a conductor's Fresnel
    times its reflection tint (if any), 1 otherwise (glass tints: :func:`_tint`); ``None``
    where no material is glossy."""
    if not any(m.glossy for m in scene.materials):
        return None
    wl = COLORIMETRIC_WAVELENGTHS
    ones = np.ones((FRESNEL_NODES, curves.shape[0]))
    return np.stack(
        [
            fresnel_table(m.metal, curves, wl, _conductor_tint(m, data_dir))
            if m.kind == "conductor"
            else ones
            for m in scene.materials
        ]
    )


def _conductor_tint(m: Material, data_dir: str | None) -> np.ndarray | None:
    """Conductor *m*'s reflection tint on the CIE grid, or ``None`` where it has none."""
    if not m.specular_reflectance:
        return None
    return get_spectrum(m.specular_reflectance, data_dir=data_dir).on(COLORIMETRIC_WAVELENGTHS)


def integration_matrix(
    bands: SensorSet,
    target: SensorSet,
    wavelengths: Wavelengths = COLORIMETRIC_WAVELENGTHS,
) -> np.ndarray:
    """``(C, K)`` matrix integrating a K-band radiance cube against C target sensors.

    Band k's raw value ``∫L B_k dλ`` divided by ``∫B_k dλ`` is the band's mean radiance; the
    radiance is taken piecewise constant over the bands, and beyond the bands' joint support
    (e.g. 360–395 and 705–830 nm for ``bands:31@400-700``) equal to the nearest band's mean,
    so ``target = T @ raw`` with ``T[c, k] = ∫B̃_k T_c dλ / ∫B_k dλ``, where B̃ extends the edge
    bands to the target's whole support. The bands must sum to 1 where they overlap, as box
    bands do.
    """
    b = bands.on(wavelengths)
    t = target.on(wavelengths)
    total = b.sum(axis=0)
    full = np.flatnonzero(total >= 1.0 - 1e-9)
    if full.size == 0:
        raise SpectralDataError(
            f"sensor set {bands.name!r}: bands must sum to 1 somewhere on the wavelength grid to be integrated"
        )
    extended = b.copy()
    idx = np.arange(np.size(wavelengths))
    # the part of the unit partition the bands leave uncovered at either end goes to the edge band
    for edge, side in ((full[0], idx < full[0]), (full[-1], idx > full[-1])):
        extended[int(np.argmax(b[:, edge])), side] += 1.0 - total[side]
    area = responses(np.ones(np.size(wavelengths)), b, wavelengths)
    return responses(t, extended, wavelengths) / area[None, :]


def regression_matrix(
    sensors: SensorSet,
    target: SensorSet,
    lights: np.ndarray,
    wavelengths: Wavelengths = COLORIMETRIC_WAVELENGTHS,
) -> np.ndarray:
    """``(C, K)`` least-squares projection from K-sensor to C target responses (thesis 5.2.3).

    Fitted on the radiances ``ρ_i(λ) L_j(λ)`` of the 1269 matte Munsell chips ρ_i (the thesis'
    colour set) under each of the scene's lights L_j, stacked: the regression knows the scene's
    illuminants, as the thesis' own regression could, but not its interreflections (products of
    several reflectances), whose error it is meant to show.

    Parameters
    ----------
    lights
        ``(J, W)`` spectra of the lights on *wavelengths*; each is normalised to unit maximum so
        every light weighs alike in the fit.
    """
    rho = family_values("munsell", wavelengths)  # read-only, cached per grid
    lights = np.atleast_2d(np.asarray(lights, float))
    if lights.shape[0] == 0:
        lights = np.ones((1, np.size(wavelengths)))
    lights = lights / np.maximum(lights.max(axis=1, keepdims=True), 1e-300)
    radiance = (rho[None, :, :] * lights[:, None, :]).reshape(-1, np.size(wavelengths))
    src = responses(radiance, sensors.on(wavelengths), wavelengths)
    dst = responses(radiance, target.on(wavelengths), wavelengths)
    return fit_projection(src, dst)


def to_xyz_matrix(
    mode: RenderMode,
    scene: Scene,
    *,
    data_dir: str | None = None,
    emitted: np.ndarray | None = None,
) -> np.ndarray:
    """``(3, K)`` matrix taking *mode*'s raw channels to CIE 1931 XYZ: ``xyz = raw @ T.T``.

    A regression mode fits it under the lights' ``(L, W)`` *emitted* spectra on the CIE grid
    (:func:`light_spectra` of *scene* where not given: a caller that needs them anyway passes
    them, computed once)."""
    sensors = get_sensors(mode.sensors, data_dir=data_dir)
    xyz = get_sensors(XYZ_SENSORS)
    if mode.to_xyz == "identity":
        if sensors.n != 3:
            raise SpectralDataError(
                f"mode {mode.name!r}: identity map to XYZ needs 3 sensors, got {sensors.n}"
            )
        return np.eye(3)
    if mode.to_xyz == "integration":
        return integration_matrix(sensors, xyz)
    if emitted is None:
        emitted = light_spectra(scene, data_dir=data_dir)
    return regression_matrix(sensors, xyz, emitted)


#: Pixels converted at a time by :func:`raw_to_xyz`: one chunk's float64 copy stays in cache.
_XYZ_CHUNK = 8192


def raw_to_xyz(
    raw: np.ndarray, matrix: np.ndarray, dtype: type[np.floating] = np.float32
) -> np.ndarray:
    """``(..., 3)`` XYZ from ``(..., K)`` raw channels with a ``(3, K)`` matrix, summed in
    float64 by einsum's own loop rather than BLAS, so the bits written do not depend on the
    BLAS kernel or its threads (and many threads may convert at once without contention);
    returned as *dtype* (float32 as stored, float64 to add several before rounding)."""
    values = np.asarray(raw)
    m = np.asarray(matrix, np.float64)
    flat = values.reshape(-1, values.shape[-1])
    out = np.empty((flat.shape[0], m.shape[0]), dtype)
    for start in range(0, flat.shape[0], _XYZ_CHUNK):
        part = slice(start, start + _XYZ_CHUNK)
        out[part] = np.einsum("nk,ck->nc", flat[part].astype(np.float64), m)
    return out.reshape(*values.shape[:-1], m.shape[0])


def pad_to_passes(values: np.ndarray) -> Sequence[np.ndarray]:
    """Split ``(N, K)`` channel values into ⌈K/3⌉ ``(N, 3)`` blocks, the last zero-padded."""
    values = np.asarray(values, float)
    n, k = values.shape
    blocks = -(-k // 3)
    padded = np.zeros((n, 3 * blocks))
    padded[:, :k] = values
    return [padded[:, 3 * i : 3 * i + 3] for i in range(blocks)]
