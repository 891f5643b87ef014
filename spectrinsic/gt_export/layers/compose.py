"""Every family together: :func:`compute_ground_truth` and the identities the layers satisfy."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...render.result import RenderResult
from ...scenes.material_labels import material_label
from ...scenes.model import Scene
from ...spectra import get_sensors, get_spectrum, white_normalised_responses
from ...spectra.working_space import WorkingSpace
from . import irradiance as irr
from .cameras import camera_layers, matrices_of
from .denoise import Denoiser, Guides, denoise_white_radiance
from .geometry import coverage_of, geometry_layers
from .gloss import SPECULAR, gloss_layers, specular_rgb
from .images import cube_layer, image_layers
from .imaging import coverage_weighted
from .intrinsics import (
    band_albedos,
    clipping_of,
    from_denoised,
    intrinsic_layers,
    noise_of,
    rgb_of,
    rgb_white,
    white_radiance,
)
from .lights import light_records, share_layers
from .records import (
    RGB,
    GroundTruth,
    Layer,
    SampleInputs,
    aov,
    camera_key,
    cube_sensor_name,
    grid,
    make_layer,
    reference_mode,
)
from .settings import LayerSettings
from .spectral import camera_curves
from .spectral_intrinsics import (
    SPECTRAL_MODE,
    residual_shares,
    spectral_identity,
    spectral_layers,
)

# Responses with the light's white at Y = 1; under D65 with sRGB sensors, the canonical p^{s,c}.

__all__ = ["compute_ground_truth", "identities"]


def _sample(scene: Scene, result: RenderResult, data_dir: Any, space: WorkingSpace) -> SampleInputs:
    wl = grid()
    rho = (
        np.stack([get_spectrum(m.spectrum, data_dir=data_dir).on(wl) for m in scene.materials])
        if scene.materials
        else np.zeros((0, wl.size))
    )
    return SampleInputs(
        scene,
        result,
        reference_mode(result),
        wl,
        rho,
        get_spectrum("cie:D65").on(wl),
        data_dir,
        space,
    )


def _reflectance(s: SampleInputs, coverage: np.ndarray) -> tuple[Layer, Any]:
    """``reflectance`` (working-space RGB under D65 of each material, the perfect white at
    Y = 1, coverage-weighted; in sRGB :func:`~spectrinsic.spectra.absolute_reflectance`) as a
    layer and in float64."""
    xyz = white_normalised_responses(s.material_rho, s.d65, get_sensors("cie1931").on(s.wl), s.wl)
    values = coverage_weighted(coverage, s.space.rgb(xyz))
    white = ", ".join(f"{v:.3f}" for v in s.space.white)
    return make_layer(
        "reflectance",
        values,
        RGB,
        f"dimensionless absolute reflectance, linear {s.space.colourspace} under D65 (perfect "
        f"white = ({white}), the space's D65 white); box-filtered by pixel coverage, 0 for "
        "background",
        "intrinsics",
    ), values


def compute_ground_truth(
    scene: Scene,
    result: RenderResult,
    settings: LayerSettings | None = None,
    *,
    denoise_quality: str = "fast",
    denoiser: Denoiser | None = None,
    training: np.ndarray | None = None,
) -> GroundTruth:
    """Compute every ground-truth layer of one rendered sample.

    Parameters
    ----------
    scene
        The scene that was rendered (names every material and light spectrum).
    result
        The render (:class:`~spectrinsic.render.result.RenderResult`).
    settings
        The layers asked for (:class:`~spectrinsic.gt_export.layers.settings.LayerSettings`,
        default ``LayerSettings()``):
        per-camera layers of ``settings.cameras`` (none when ``None``), the cube, the per-band
        layers, the working space of the RGB layers (ACEScg by default, shading negatives
        kept; ``srgb``: the layers of before, shading clipped at 0). With ``denoise`` the
        white-surface radiance is denoised with OIDN (:mod:`~spectrinsic.gt_export.layers.denoise`):
        ``shading``, ``residual``, ``illuminant``, ``shading_grey`` and the camera shading
        come from it, ``image_denoised = reflectance ∘ shading + residual`` is rebuilt from it,
        and the raw ``shading_raw``/``residual_raw`` are kept beside ``image``. Its camera
        chain and noise id are the writer's (:func:`~spectrinsic.gt_export.sample.writer.export_sample`).
    denoise_quality
        OIDN quality, ``"fast"`` (the dataset's, :data:`~spectrinsic.gt_export.layers.denoise.DENOISE_QUALITY`)
        or ``"high"``.
    denoiser
        With ``settings.denoise``, the function that denoises ``W`` given its guides, instead of
        :func:`~spectrinsic.gt_export.layers.denoise.denoise_white_radiance` (``make bench`` scores
        alternatives with it).
    training
        ``(N, 471)`` reflectances on the 1 nm grid for the matrix fits (default: all Munsell chips).
    """
    settings = settings or LayerSettings()
    cameras, denoise, data_dir = settings.cameras or (), settings.denoise, settings.data_dir
    s = _sample(scene, result, data_dir, settings.working_space)
    layers = image_layers(s)
    image = layers[0].data.astype(np.float64)
    coverage, mask = coverage_of(s, (image.shape[0], image.shape[1]))
    layers += geometry_layers(s, mask)
    reflectance_layer, reflectance = _reflectance(s, coverage)
    layers.append(reflectance_layer)
    w_raw = white_radiance(s, coverage)
    w = w_raw
    if denoise:
        guides = Guides(aov(result, "normals"), aov(result, "depth"))
        w = (
            denoise_white_radiance(w_raw, guides, quality=denoise_quality)
            if denoiser is None
            else denoiser(w_raw, guides)
        )
        batches = tuple(b[s.ref] for b in result.batch_raw if s.ref in b)
        w = irr.unlit_masked(w, w_raw, batches)
    specular = specular_rgb(s, w_raw.to_xyz)
    layers += intrinsic_layers(s, w_raw, w, image, reflectance, denoised=denoise, specular=specular)
    layers += gloss_layers(s, coverage, specular)
    noise_maps, noise = noise_of(s, w_raw)
    light_maps, shares = share_layers(s, w, mask)
    layers += noise_maps + light_maps
    spaces: dict[str, np.ndarray] = {"srgb": get_sensors("srgb").on(s.wl)}
    spaces.update({cam: camera_curves(cam, s.wl, data_dir=data_dir) for cam in cameras})
    if cameras and "bands31" not in result.raw:
        raise DatasetError(
            "camera images need the 31-band cube (render mode 'bands31'); render it or pass cameras=()"
        )
    for cam in cameras:
        layers += camera_layers(s, cam, spaces[cam], coverage, w, denoised=denoise)
    cube_name = cube_sensor_name(result) if "bands31" in result.raw else None
    if settings.write_cube:
        layers.append(cube_layer(s, cube_name))
    if settings.spectral_layers:
        layers += spectral_layers(s, coverage, w_raw, w, denoised=denoise)
    by_name = {layer.name: layer for layer in layers}
    return GroundTruth(
        layers=by_name,
        lights=light_records(s, shares, spaces, cameras),
        materials={str(i): material_label(m) for i, m in enumerate(scene.materials)},
        matrices=matrices_of(s, shares, spaces, training),
        reference_mode=s.ref,
        cameras=tuple(cameras),
        cube_sensors=cube_name,
        denoised=tuple(
            sorted(layer.name for layer in layers if denoise and from_denoised(layer.name))
        ),
        noise=noise,
        clipping=clipping_of(rgb_of(s, w) / rgb_white(s), w.valid & (irr.luminance_of(w) > 0)),
        working_space=s.space,
        residual_share=residual_shares(_identities(by_name, cameras), by_name, mask),
        band_albedos=_band_albedos(s) if settings.spectral_layers else None,
    )


def _band_albedos(s: SampleInputs) -> np.ndarray:
    """The materials' band albedos on the 31-band grid (the per-band layers' factors)."""
    return band_albedos(dataclasses.replace(s, ref=SPECTRAL_MODE))


def identities(gt: GroundTruth) -> list[dict[str, str]]:
    """The exact identities the layers satisfy: ``image = reflectance ∘ shading [+ specular] +
    residual`` per sensor space (and on the raw layers when denoised), the specular term only in
    glossy scenes, and per band with the spectral layers; recorded in ``meta.json``."""
    return _identities(gt.layers, gt.cameras)


def _identities(layers: dict[str, Any], cameras: Sequence[str]) -> list[dict[str, str]]:
    out = []
    denoised = "image_denoised" in layers
    glossy = SPECULAR in layers
    spec = {SPECULAR: SPECULAR} if glossy else {}
    out.append(
        {
            "image": "image_denoised" if denoised else "image",
            "reflectance": "reflectance",
            "shading": "shading",
            "residual": "residual",
        }
        | spec
    )
    if denoised:
        out.append(
            {
                "image": "image",
                "reflectance": "reflectance",
                "shading": "shading_raw",
                "residual": "residual_raw",
            }
            | spec
        )
    for cam in cameras:
        key = camera_key(cam)
        image = f"image_camera_denoised/{key}" if denoised else f"image_camera/{key}"
        out.append(
            {
                "image": image,
                "reflectance": f"reflectance_camera/{key}",
                "shading": f"shading_camera/{key}",
                "residual": f"residual_camera/{key}",
            }
            | ({SPECULAR: f"{SPECULAR}_camera/{key}"} if glossy else {})
        )
    spectral = spectral_identity(layers)
    return out if spectral is None else [*out, spectral]
