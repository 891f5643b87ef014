"""``render_scene``: every requested mode of one scene, converted to XYZ, with AOVs."""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence

import numpy as np

from spectrinsic.errors import RenderError, SceneError
from spectrinsic.render.modes import (
    RenderMode,
    channel_values,
    get_mode,
    n_passes,
    raw_to_xyz,
    to_xyz_matrix,
)
from spectrinsic.render.passes import (
    PassOutput,
    Progress,
    render_aovs,
    render_diagonal,
    render_spectral,
)
from spectrinsic.render.result import RenderResult
from spectrinsic.scenes.model import Scene
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS, get_sensors

__all__ = ["DEFAULT_MODES", "render_scene", "count_passes"]

logger = logging.getLogger(__name__)

DEFAULT_MODES: tuple[str, ...] = ("spectral", "rgb3", "rgb6", "bands31")


def _modes(modes: Iterable[str]) -> list[RenderMode]:
    names = list(dict.fromkeys(modes))
    if not names:
        raise SceneError("modes: expected at least one render mode, e.g. 'rgb3'")
    return [get_mode(m) for m in names]


def _direct_modes(direct: bool | Iterable[str], modes: Sequence[RenderMode]) -> set[str]:
    if direct is True:
        return {m.name for m in modes}
    if direct is False or direct is None:
        return set()
    wanted = {get_mode(m).name for m in direct}  # type: ignore[union-attr]
    missing = wanted - {m.name for m in modes}
    if missing:
        raise SceneError(f"direct modes {sorted(missing)} are not among the rendered modes {[m.name for m in modes]}")
    return wanted


def count_passes(
    scene: Scene,
    modes: Iterable[str] = DEFAULT_MODES,
    *,
    per_light: bool = False,
    direct: bool | Iterable[str] = False,
    aovs: bool = True,
    data_dir: str | None = None,
) -> int:
    """Number of Mitsuba passes :func:`render_scene` runs (the total of its progress calls)."""
    objs = _modes(modes)
    wanted = _direct_modes(direct, objs)
    groups = len(scene.lights) if per_light else 1
    colour = sum(n_passes(m, data_dir=data_dir) * (2 if m.name in wanted else 1) for m in objs)
    from spectrinsic.render.translate import surfaces

    return groups * colour + (max(1, -(-len(surfaces(scene)) // 3)) if aovs else 0)


def _sum_direct(parts: Sequence[np.ndarray | None]) -> np.ndarray:
    """Sum of the direct-only renders of every light group (each was asked for)."""
    present = [p for p in parts if p is not None]
    if len(present) != len(parts):
        raise RenderError("a direct-only render is missing for a light group")
    return np.sum(present, axis=0, dtype=np.float64)


def render_scene(
    scene: Scene,
    *,
    modes: Iterable[str] = DEFAULT_MODES,
    spp: int,
    seed: int,
    max_depth: int = 8,
    variant: str | None = None,
    per_light: bool = False,
    direct: bool | Iterable[str] = False,
    aovs: bool = True,
    progress: Progress | None = None,
    data_dir: str | None = None,
) -> RenderResult:
    """Render *scene* in each of *modes* and convert every mode to CIE 1931 XYZ.

    All diagonal modes share one loaded scene and the same paths (same seed and sample count,
    Russian roulette off): ``rgb3``, ``rgb6`` and ``bands31`` differ only by spectral error.

    Parameters
    ----------
    modes
        Names from :data:`spectrinsic.render.modes.RENDER_MODES`.
    spp, seed
        Samples per pixel and sampler seed, shared by every pass.
    max_depth
        Longest path (Mitsuba convention: 2 = direct light only).
    variant
        Backend (``"cuda"``, ``"llvm"``, ``"scalar"``) or variant name; default: the best usable.
    per_light
        Also render each light alone (one scene per light); ``images`` is then exactly the sum
        of the per-light images (and ``direct`` of per-light direct images), costing no extra.
    direct
        ``True`` for a direct-only render of every mode, or an iterable of the modes that need
        one (e.g. only the reference, for r of Eq. 5.8).
    aovs
        Also compute coverage, ids, depth and normals (:func:`~spectrinsic.render.passes.render_aovs`).
    progress
        Called with 1 after each Mitsuba pass; :func:`count_passes` gives the total.

    Returns
    -------
    RenderResult
    """
    objs = _modes(modes)
    wanted = _direct_modes(direct, objs)
    sensors = {m.name: get_sensors(m.sensors, data_dir=data_dir) for m in objs}
    matrices = {m.name: to_xyz_matrix(m, scene, data_dir=data_dir) for m in objs}
    diagonal = [m for m in objs if m.kind == "diagonal"]
    values = [channel_values(scene, sensors[m.name], data_dir=data_dir) for m in diagonal]
    groups: list[Sequence[int] | None] = [[j] for j in range(len(scene.lights))] if per_light else [None]

    from spectrinsic.render.translate import prepare_geometry
    from spectrinsic.render.variants import choose_variant, import_mitsuba, variant_scope

    geometry = prepare_geometry(scene)
    timings: dict[str, list[float]] = {m.name: [] for m in objs}
    variants: dict[str, str] = {}
    raw_groups: list[dict[str, PassOutput]] = [{} for _ in groups]
    aov_maps: dict[str, np.ndarray] = {}
    # Passes are grouped by Mitsuba variant: each switch between the RGB and the spectral variant
    # reloads Mitsuba's Python modules (~0.1 s), so every RGB-variant pass (all diagonal modes of
    # every light group, then the AOVs) runs in one scope and every spectral pass in another.
    # Passes do not depend on each other's order: each sets its own values, seed and spp.
    if diagonal or aovs:
        rgb_variant = choose_variant("rgb", variant)
        with variant_scope(rgb_variant):
            for outputs, group in zip(raw_groups, groups, strict=True):
                if diagonal:
                    outputs.update(zip((m.name for m in diagonal), render_diagonal(
                        scene, values, spp=spp, seed=seed, max_depth=max_depth,
                        direct=[m.name in wanted for m in diagonal], active_lights=group,
                        variant=rgb_variant, progress=progress, geometry=geometry,
                    ), strict=True))
            if aovs:
                aov_maps, aov_seconds = render_aovs(scene, spp=spp, seed=seed, variant=rgb_variant,
                                                    progress=progress, geometry=geometry)
    spectral = [m for m in objs if m.kind == "spectral"]
    if spectral:
        spectral_variant = choose_variant("spectral", variant)
        with variant_scope(spectral_variant):
            for outputs, group in zip(raw_groups, groups, strict=True):
                for m in spectral:
                    outputs[m.name] = render_spectral(
                        scene, sensors[m.name], spp=spp, seed=seed, max_depth=max_depth, direct=m.name in wanted,
                        active_lights=group, variant=spectral_variant, data_dir=data_dir,
                        progress=progress, geometry=geometry,
                    )
    for outputs in raw_groups:
        for name, out in outputs.items():
            timings[name].extend(out.seconds)
            variants[name] = out.variant

    names = [m.name for m in objs]
    raw = {n: np.sum([g[n].image for g in raw_groups], axis=0, dtype=np.float64).astype(np.float32) for n in names}
    images = {n: raw_to_xyz(raw[n], matrices[n]) for n in names}
    lights = tuple({n: raw_to_xyz(g[n].image, matrices[n]) for n in names} for g in raw_groups) if per_light else ()
    direct_images = {
        n: raw_to_xyz(_sum_direct([g[n].direct for g in raw_groups]), matrices[n])
        for n in names if n in wanted
    }
    if aovs:
        timings["aovs"] = list(aov_seconds)

    meta = {
        "mitsuba": import_mitsuba().__version__,
        "variants": variants,
        "spp": int(spp),
        "seed": int(seed),
        "max_depth": int(max_depth),
        "modes": names,
        "sensors": {n: sensors[n].name for n in names},
        "to_xyz": {n: np.asarray(matrices[n]).tolist() for n in names},
        "wavelengths": {
            "start": float(COLORIMETRIC_WAVELENGTHS[0]), "end": float(COLORIMETRIC_WAVELENGTHS[-1]),
            "step": float(COLORIMETRIC_WAVELENGTHS[1] - COLORIMETRIC_WAVELENGTHS[0]), "unit": "nm",
        },
        "per_light": bool(per_light),
        "direct_modes": sorted(wanted),
        "timings": {k: {"passes": len(v), "seconds": float(sum(v)), "per_pass": [float(x) for x in v]}
                    for k, v in timings.items()},
        "units": "XYZ = integral of radiance times CIE 1931 CMF over nm; raw = integral of radiance times S_k",
    }
    logger.debug("rendered %s: %s", scene.name, {k: v["seconds"] for k, v in meta["timings"].items()})
    return RenderResult(images=images, raw=raw, per_light=lights, direct=direct_images, aovs=aov_maps, meta=meta)
