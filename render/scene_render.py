"""``render_scene``: every requested mode of one scene, converted to XYZ, with AOVs."""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

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
    PassProgress,
    render_aovs,
    render_diagonal,
    render_spectral,
)
from spectrinsic.render.result import RenderResult
from spectrinsic.render.settings import DEFAULT_MODES, RenderSettings
from spectrinsic.render.single import SingleTraversal, render_jobs, resolve_integrator
from spectrinsic.render.translate import prepare_geometry, surfaces
from spectrinsic.render.variants import choose_variant, import_mitsuba, variant_scope
from spectrinsic.rng import seed_from_key
from spectrinsic.scenes.model import Scene
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS, get_sensors

__all__ = [
    "DEFAULT_MODES",
    "render_scene",
    "render_batches",
    "batch_seeds",
    "merge_batches",
    "image_noise",
    "relative_standard_error",
    "count_passes",
]

logger = logging.getLogger(__name__)


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
        raise SceneError(
            f"direct modes {sorted(missing)} are not among the rendered modes {[m.name for m in modes]}"
        )
    return wanted


def count_passes(scene: Scene, settings: RenderSettings, *, data_dir: str | None = None) -> int:
    """Number of Mitsuba passes :func:`render_scene` runs (the total of its progress calls)."""
    modes, per_light, per_light_modes = settings.modes, settings.per_light, settings.per_light_modes
    direct, aovs = settings.direct, settings.aovs
    objs = _modes(modes)
    wanted = _direct_modes(direct, objs)
    split = per_light and per_light_modes is not None
    groups = len(scene.lights) if per_light and not split else 1
    share_modes = _modes(per_light_modes) if per_light and per_light_modes is not None else []
    single = resolve_integrator(settings.integrator, settings.variant) == "single" and any(
        m.kind == "diagonal" for m in objs + share_modes
    )
    diagonal = 0
    if single:  # every diagonal mode and the AOVs: one traversal (+1 direct-only)
        diagonal = 1 + any(m.kind == "diagonal" and m.name in wanted for m in objs)
        objs, share_modes = (
            [m for m in objs if m.kind != "diagonal"],
            [m for m in share_modes if m.kind != "diagonal"],
        )
    colour = sum(n_passes(m, data_dir=data_dir) * (2 if m.name in wanted else 1) for m in objs)
    shares = sum(n_passes(m, data_dir=data_dir) for m in share_modes)

    aov_passes = max(1, -(-len(surfaces(scene)) // 3)) if aovs and not single else 0
    return diagonal + groups * colour + len(scene.lights) * shares + aov_passes


def _sum_direct(parts: Sequence[np.ndarray | None]) -> np.ndarray:
    """Sum of the direct-only renders of every light group (each was asked for)."""
    present = [p for p in parts if p is not None]
    if len(present) != len(parts):
        raise RenderError("a direct-only render is missing for a light group")
    return np.sum(present, axis=0, dtype=np.float64)


@dataclass(frozen=True)
class _Job:
    """One set of passes: some modes with some lights on (``None``: all)."""

    modes: tuple[RenderMode, ...]
    group: Sequence[int] | None
    #: Whether the modes asked for a direct-only render get one in this job.
    with_direct: bool = True


@dataclass(frozen=True)
class _Run:
    """What every pass of one :func:`_run_jobs` call shares."""

    scene: Scene
    jobs: Sequence[_Job]
    wanted: set[str]
    aovs: bool
    data_dir: str | None
    integrator: str
    common: dict[str, Any]
    #: One dict mode -> pass output per job, filled by the parts.
    outputs: list[dict[str, PassOutput]]


def _rgb_part(
    run: _Run, rgb_variant: str
) -> tuple[dict[str, np.ndarray], tuple[float, ...], SingleTraversal]:
    """The diagonal modes of every job (one traversal, or the passes) and the AOVs."""
    scene, common, single = run.scene, run.common, SingleTraversal({}, ())
    aov_maps: dict[str, np.ndarray] = {}
    if run.integrator == "single":
        parts, single = render_jobs(
            scene,
            [(j.modes, j.group, j.with_direct) for j in run.jobs],
            wanted=run.wanted,
            variant=rgb_variant,
            data_dir=run.data_dir,
            aovs=run.aovs,
            **common,
        )
        aov_maps = single.aovs
        for out, part in zip(run.outputs, parts, strict=True):
            out.update(part)
        return aov_maps, (), single
    for out, job in zip(run.outputs, run.jobs, strict=True):
        diagonal = [m for m in job.modes if m.kind == "diagonal"]
        values = [
            channel_values(
                scene, get_sensors(m.sensors, data_dir=run.data_dir), data_dir=run.data_dir
            )
            for m in diagonal
        ]
        out.update(
            zip(
                (m.name for m in diagonal),
                render_diagonal(
                    scene,
                    values,
                    direct=[job.with_direct and m.name in run.wanted for m in diagonal],
                    active_lights=job.group,
                    variant=rgb_variant,
                    **common,
                ),
                strict=True,
            )
            if diagonal
            else ()
        )
    if not run.aovs:
        return aov_maps, (), single
    aov_maps, aov_seconds = render_aovs(
        scene,
        spp=common["spp"],
        seed=common["seed"],
        variant=rgb_variant,
        progress=common["progress"],
        geometry=common["geometry"],
    )
    return aov_maps, aov_seconds, single


def _spectral_part(run: _Run, spectral_variant: str) -> None:
    """The spectral passes of every job."""
    for out, job in zip(run.outputs, run.jobs, strict=True):
        for m in (m for m in job.modes if m.kind == "spectral"):
            out[m.name] = render_spectral(
                run.scene,
                get_sensors(m.sensors, data_dir=run.data_dir),
                direct=job.with_direct and m.name in run.wanted,
                active_lights=job.group,
                variant=spectral_variant,
                data_dir=run.data_dir,
                **run.common,
            )


def _run_jobs(
    scene: Scene,
    jobs: Sequence[_Job],
    *,
    wanted: set[str],
    spp: int,
    seed: int,
    max_depth: int,
    variant: str | None,
    aovs: bool,
    progress: PassProgress | None,
    data_dir: str | None,
    integrator: str = "passes",
) -> tuple[list[dict[str, PassOutput]], dict[str, np.ndarray], tuple[float, ...], SingleTraversal]:
    """Every pass of *jobs*, grouped by Mitsuba variant, plus the AOVs.

    Each switch between the RGB and the spectral variant reloads Mitsuba's Python modules
    (0.25 s on the 2-core machine, measured: 8 switches were 2.0 s of a 14.5 s default sample),
    so every RGB-variant pass (all diagonal modes of every job, then the AOVs) runs in one
    scope and every spectral pass in another; the variant already active goes first and stays
    active afterwards (``restore=False``), so consecutive batches switch once each, not four
    times. Passes do not depend on each other's order: each sets its own values, seed and spp.
    With ``integrator="single"`` the diagonal modes of every job come from one band-path
    traversal (:func:`spectrinsic.render.single.render_jobs`).
    """
    diagonal = any(m.kind == "diagonal" for job in jobs for m in job.modes)
    run = _Run(
        scene,
        jobs,
        wanted,
        aovs,
        data_dir,
        integrator if diagonal else "passes",
        dict(
            spp=spp,
            seed=seed,
            max_depth=max_depth,
            progress=progress,
            geometry=prepare_geometry(scene),
        ),
        [{} for _ in jobs],
    )
    found: tuple[dict[str, np.ndarray], tuple[float, ...], SingleTraversal] = (
        {},
        (),
        SingleTraversal({}, ()),
    )
    parts = []
    if aovs or diagonal:
        parts.append(("rgb", choose_variant("rgb", variant)))
    if any(m.kind == "spectral" for job in jobs for m in job.modes):
        parts.append(("spectral", choose_variant("spectral", variant)))
    for kind, chosen in sorted(parts, key=lambda p: p[1] != import_mitsuba().variant()):
        with variant_scope(chosen, restore=False):
            if kind == "rgb":
                found = _rgb_part(run, chosen)
            else:
                _spectral_part(run, chosen)
    return run.outputs, *found


def render_scene(
    scene: Scene,
    settings: RenderSettings,
    *,
    seed: int,
    progress: PassProgress | None = None,
    data_dir: str | None = None,
) -> RenderResult:
    """Render *scene* in each of ``settings.modes`` and convert every mode to CIE 1931 XYZ.

    One batch: every pass renders ``settings.batch_spp`` samples with sampler seed *seed*.
    All diagonal modes share one loaded scene and the same paths (same seed and sample count,
    Russian roulette off): ``rgb3``, ``rgb6`` and ``bands31`` differ only by spectral error.
    With ``settings.per_light`` and no ``share_mode`` every mode is rendered light by light and
    ``images`` is exactly the sum of the per-light images (and ``direct`` of per-light direct
    images), costing no extra.

    Parameters
    ----------
    settings
        Modes, samples, path depth, variant, per-light, direct and AOV choices
        (:class:`~spectrinsic.render.settings.RenderSettings`), and the integrator of the
        diagonal modes: ``"passes"``, ⌈K/3⌉ RGB passes per mode and one scene per light;
        ``"single"`` (default), one traversal for every diagonal mode, band and light
        (:mod:`spectrinsic.render.single`): the same images to float rounding, per-light
        images that are exact shares of the full render, and ``RenderResult.transport``.
    seed
        Sampler seed, shared by every pass.
    progress
        Called with 1 after each Mitsuba pass; :func:`count_passes` gives the total.

    Returns
    -------
    RenderResult
    """
    modes, spp, max_depth, per_light = (
        settings.modes,
        settings.batch_spp,
        settings.max_depth,
        settings.per_light,
    )
    per_light_modes, direct, aovs, variant = (
        settings.per_light_modes,
        settings.direct,
        settings.aovs,
        settings.variant,
    )
    objs = _modes(modes)
    wanted = _direct_modes(direct, objs)
    integrator = resolve_integrator(settings.integrator, variant)
    if (
        integrator == "passes"
        and any(m.glossy for m in scene.materials)
        and any(m.kind == "diagonal" for m in objs)
    ):
        raise RenderError(
            f"scene {scene.name!r} has glossy materials: diagonal modes render them only with "
            "integrator 'single' on a JIT (LLVM/CUDA) variant; spectral modes render them either way"
        )
    matrices = {m.name: to_xyz_matrix(m, scene, data_dir=data_dir) for m in objs}
    lights = [[j] for j in range(len(scene.lights))]
    split = per_light and per_light_modes is not None
    share = _modes(per_light_modes) if per_light and per_light_modes is not None else []
    main = [_Job(tuple(objs), g) for g in (lights if per_light and not split else [None])]
    jobs = main + [_Job(tuple(share), g, with_direct=False) for g in lights] if split else main
    outputs, aov_maps, aov_seconds, single = _run_jobs(
        scene,
        jobs,
        wanted=wanted,
        spp=spp,
        seed=seed,
        max_depth=max_depth,
        variant=variant,
        aovs=aovs,
        progress=progress,
        data_dir=data_dir,
        integrator=integrator,
    )
    main_out, share_out = outputs[: len(main)], outputs[len(main) :]
    timings: dict[str, list[float]] = {m.name: [] for m in objs + share}
    variants: dict[str, str] = {}
    for out in outputs:
        for name, o in out.items():
            timings[name].extend(o.seconds)
            variants[name] = o.variant
    names = [m.name for m in objs]
    raw = {
        n: np.sum([g[n].image for g in main_out], axis=0, dtype=np.float64).astype(np.float32)
        for n in names
    }
    images = {n: raw_to_xyz(raw[n], matrices[n]) for n in names}
    if split:
        share_xyz = {m.name: to_xyz_matrix(m, scene, data_dir=data_dir) for m in share}
        per_light_images = tuple(
            {n: raw_to_xyz(g[n].image, share_xyz[n]) for n in share_xyz} for g in share_out
        )
    elif per_light:
        per_light_images = tuple(
            {n: raw_to_xyz(g[n].image, matrices[n]) for n in names} for g in main_out
        )
    else:
        per_light_images = ()
    direct_images = {
        n: raw_to_xyz(_sum_direct([g[n].direct for g in main_out]), matrices[n])
        for n in names
        if n in wanted
    }
    if aovs:
        timings["aovs"] = list(aov_seconds)
    if single.seconds:
        timings["single"] = list(single.seconds)
    meta = _render_meta(
        scene,
        objs,
        matrices,
        variants,
        timings,
        spp=spp,
        seed=seed,
        max_depth=max_depth,
        per_light=per_light,
        wanted=wanted,
        data_dir=data_dir,
    )
    meta["per_light_modes"] = [m.name for m in share] if split else (names if per_light else [])
    meta["integrator"] = integrator
    logger.debug(
        "rendered %s: %s", scene.name, {k: v["seconds"] for k, v in meta["timings"].items()}
    )
    return RenderResult(
        images=images,
        raw=raw,
        per_light=per_light_images,
        direct=direct_images,
        aovs=aov_maps,
        meta=meta,
        transport={n: t.transport for n, t in single.transport.items()},
        specular=_specular_raw(single, [job.group for job in main]),
    )


def _specular_raw(
    single: SingleTraversal, groups: Sequence[Sequence[int] | None]
) -> dict[str, np.ndarray]:
    """Mode -> raw specular channels (glossy scenes), summed over the light *groups* of the
    main jobs exactly as ``raw`` is, so ``raw − specular`` is exactly 0 where all is specular."""
    out = {}
    for name, t in single.transport.items():
        if t.specular is not None:
            parts = [p for g in groups if (p := t.specular_image(g)) is not None]
            out[name] = np.sum(parts, axis=0, dtype=np.float64).astype(np.float32)
    return out


def _render_meta(
    scene: Scene,
    objs: Sequence[RenderMode],
    matrices: dict[str, np.ndarray],
    variants: dict[str, str],
    timings: dict[str, list[float]],
    *,
    spp: int,
    seed: int,
    max_depth: int,
    per_light: bool,
    wanted: set[str],
    data_dir: str | None,
) -> dict[str, Any]:
    names = [m.name for m in objs]
    return {
        "mitsuba": import_mitsuba().__version__,
        "variants": variants,
        "spp": int(spp),
        "seed": int(seed),
        "max_depth": int(max_depth),
        "modes": names,
        "sensors": {m.name: get_sensors(m.sensors, data_dir=data_dir).name for m in objs},
        "to_xyz": {n: np.asarray(matrices[n]).tolist() for n in names},
        "wavelengths": {
            "start": float(COLORIMETRIC_WAVELENGTHS[0]),
            "end": float(COLORIMETRIC_WAVELENGTHS[-1]),
            "step": float(COLORIMETRIC_WAVELENGTHS[1] - COLORIMETRIC_WAVELENGTHS[0]),
            "unit": "nm",
        },
        "per_light": bool(per_light),
        "direct_modes": sorted(wanted),
        "timings": {
            k: {"passes": len(v), "seconds": float(sum(v)), "per_pass": [float(x) for x in v]}
            for k, v in timings.items()
        },
        "units": "XYZ = integral of radiance times CIE 1931 CMF over nm; raw = integral of radiance times S_k",
    }


def batch_seeds(seed: int, batches: int) -> list[int]:
    """Sampler seeds of *batches* independent batches: the sample's own seed first (so one
    batch is exactly :func:`render_scene`), then seeds derived from it by key."""
    if isinstance(batches, bool) or not isinstance(batches, int) or batches < 1:
        raise SceneError(f"batches {batches!r}: expected a positive integer")
    return [int(seed)] + [seed_from_key(int(seed), f"batch-{b}") for b in range(1, batches)]


def render_batches(
    scene: Scene,
    settings: RenderSettings,
    *,
    seed: int,
    progress: PassProgress | None = None,
    data_dir: str | None = None,
) -> RenderResult:
    """:func:`render_scene` as ``settings.batches`` independent batches, merged.

    Inside a batch every mode and the AOVs share seed and paths (common random numbers); the
    batches differ only in their seed (:func:`batch_seeds`), so the spread between them is a
    direct estimate of the Monte Carlo error of their mean (the noise budget of the ground
    truth).

    Adaptive sampling: with ``settings.noise_target``, batches are added one at a time while
    the median relative standard error of the image (:func:`image_noise`) is above it, up to
    ``settings.max_batches`` (default ``4 * batches``). ``meta["noise_target"]`` records the
    target and the median reached.
    """
    batches, noise_target = settings.batches, settings.noise_target
    cap = max(batches, settings.max_batches if settings.max_batches is not None else 4 * batches)
    seeds = batch_seeds(seed, cap if noise_target is not None else batches)

    def one(s: int) -> RenderResult:
        return render_scene(scene, settings, seed=s, progress=progress, data_dir=data_dir)

    results = [one(s) for s in seeds[:batches]]
    reached = image_noise(results) if noise_target is not None else None
    while (
        reached is not None
        and noise_target is not None
        and reached > noise_target
        and len(results) < cap
    ):
        results.append(one(seeds[len(results)]))
        reached = image_noise(results)
    merged = merge_batches(results)
    if noise_target is not None:
        merged.meta["noise_target"] = {
            "target": float(noise_target),
            "reached": reached,
            "max_batches": cap,
        }
    return merged


def relative_standard_error(batches: Sequence[np.ndarray], valid: np.ndarray) -> np.ndarray:
    """Per-pixel relative standard error of the mean of independent batch estimates.

    ``se = sqrt(Σ_b ‖x_b − x̄‖² / (B (B − 1)))`` over channels, divided by ``‖x̄‖``; 0 where
    not *valid* or where ``‖x̄‖`` is below 1e-3 of its 99th percentile (unlit).

    Parameters
    ----------
    batches
        ``B >= 2`` arrays ``(H, W, C)``, one estimate per independent batch.
    """
    stack = np.stack([np.asarray(b, np.float64) for b in batches])
    if stack.shape[0] < 2:
        raise RenderError("a noise estimate needs at least two independent batches")
    mean = stack.mean(axis=0)
    b = stack.shape[0]
    se = np.sqrt(((stack - mean) ** 2).sum(axis=(0, -1)) / (b * (b - 1)))
    norm = np.linalg.norm(mean, axis=-1)
    positive = norm[valid & (norm > 0)]
    floor = 1e-3 * np.percentile(positive, 99) if positive.size else np.inf
    ok = valid & (norm > floor)
    return np.where(ok, se / np.where(ok, norm, 1.0), 0.0)


def image_noise(results: Sequence[RenderResult]) -> float | None:
    """Median over lit pixels of the relative standard error of the mean image (XYZ of the
    31-band cube, else of the first mode), from independent batch renders; ``None`` for fewer
    than two."""
    if len(results) < 2:
        return None
    images = results[0].images
    mode = "bands31" if "bands31" in images else next(iter(images))
    stack = [np.asarray(r.images[mode], np.float64) for r in results]
    rel = relative_standard_error(stack, np.ones(stack[0].shape[:2], bool))
    return float(np.median(rel[rel > 0])) if (rel > 0).any() else 0.0


def _mean(arrays: Sequence[np.ndarray]) -> np.ndarray:
    return np.mean(np.stack(arrays), axis=0, dtype=np.float64).astype(np.float32)


def _merge_aovs(parts: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Coverage, depth and normals averaged over the batches (each batch's AOVs saw that
    batch's own pixel samples); the integer maps and the mask are those of the first batch."""
    if not parts or not parts[0]:
        return {}
    merged = dict(parts[0])
    for key in ("coverage", "depth", "normals"):
        if key in merged:
            merged[key] = _mean([p[key] for p in parts])
    if "normals" in merged:
        n = merged["normals"].astype(np.float64)
        length = np.linalg.norm(n, axis=-1, keepdims=True)
        merged["normals"] = np.divide(n, length, out=np.zeros_like(n), where=length > 1e-6).astype(
            np.float32
        )
    return merged


def merge_batches(results: Sequence[RenderResult]) -> RenderResult:
    """The mean of independent batch renders of one scene, keeping each batch's raw channels."""
    if not results:
        raise RenderError("no batches to merge")
    if len(results) == 1:
        return results[0]
    first = results[0]
    modes = list(first.images)
    meta = dict(first.meta)
    meta.update(
        spp=int(first.meta["spp"]) * len(results),
        batches=len(results),
        batch_spp=int(first.meta["spp"]),
        batch_seeds=[int(r.meta["seed"]) for r in results],
        timings={
            k: {
                "passes": sum(r.meta["timings"][k]["passes"] for r in results),
                "seconds": sum(r.meta["timings"][k]["seconds"] for r in results),
                "per_pass": [x for r in results for x in r.meta["timings"][k]["per_pass"]],
            }
            for k in first.meta["timings"]
        },
    )
    return RenderResult(
        images={m: _mean([r.images[m] for r in results]) for m in modes},
        raw={m: _mean([r.raw[m] for r in results]) for m in first.raw},
        per_light=tuple(
            {m: _mean([r.per_light[i][m] for r in results]) for m in pl}
            for i, pl in enumerate(first.per_light)
        ),
        direct={m: _mean([r.direct[m] for r in results]) for m in first.direct},
        aovs=_merge_aovs([r.aovs for r in results]),
        transport={m: _mean([r.transport[m] for r in results]) for m in first.transport},
        specular={m: _mean([r.specular[m] for r in results]) for m in first.specular},
        meta=meta,
        batch_raw=tuple(dict(r.raw) for r in results),
    )
