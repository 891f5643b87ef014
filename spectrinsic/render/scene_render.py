"""``render_scene``: every requested mode of one scene, converted to XYZ, with AOVs."""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..errors import RenderError, SceneError
from ..scenes.model import Scene
from ..spectra import COLORIMETRIC_WAVELENGTHS, get_sensors
from .algebra.modes import RenderMode, channel_values, get_mode, n_passes, raw_to_xyz, to_xyz_matrix
from .band_path.traversal import SingleTraversal, render_jobs, resolve_integrator
from .base.geometry import prepare_geometry
from .base.one_pass import PassOutput, PassProgress, timing
from .base.translate import surfaces
from .base.variants import choose_variant, import_mitsuba, variant_scope
from .passes import render_diagonal
from .passes.aovs import render_aovs
from .result import PARTS, RenderResult
from .settings import PassRequest, RenderSettings
from .spectral import render_spectral

__all__ = ["render_scene", "count_passes"]

logger = logging.getLogger(__name__)


def _modes(modes: Iterable[str]) -> list[RenderMode]:
    names = list(dict.fromkeys(modes))
    if not names:
        raise SceneError("modes: expected at least one render mode, e.g. 'rgb3'")
    return [get_mode(m) for m in names]


def _direct_modes(direct: bool | tuple[str, ...], modes: Sequence[RenderMode]) -> set[str]:
    if isinstance(direct, bool):
        return {m.name for m in modes} if direct else set()
    wanted = {get_mode(m).name for m in direct}
    missing = wanted - {m.name for m in modes}
    if missing:
        raise SceneError(
            f"direct modes {sorted(missing)} are not among the rendered modes {[m.name for m in modes]}"
        )
    return wanted


def count_passes(scene: Scene, settings: RenderSettings, *, data_dir: str | None = None) -> int:
    """Number of Mitsuba passes :func:`render_scene` runs (the total of its progress calls),
    from the same plan (and so the same integrator) as the render."""
    plan = _plan(scene, settings, data_dir)
    objs, share = plan.objs, plan.share
    diagonal = 0
    if plan.traversal:  # every diagonal mode and the AOVs: one traversal (+1 direct-only)
        diagonal = 1 + any(m.kind == "diagonal" and m.name in plan.wanted for m in objs)
        objs = [m for m in objs if m.kind != "diagonal"]
        share = [m for m in share if m.kind != "diagonal"]
    colour = sum(n_passes(m, data_dir=data_dir) * (2 if m.name in plan.wanted else 1) for m in objs)
    shares = sum(n_passes(m, data_dir=data_dir) for m in share)
    aovs = settings.aovs and not plan.traversal
    aov_passes = max(1, -(-len(surfaces(scene)) // 3)) if aovs else 0
    return diagonal + plan.n_main * colour + len(scene.lights) * shares + aov_passes


@dataclass(frozen=True)
class _Job:
    """One set of passes: some modes with some lights on (``None``: all)."""

    modes: tuple[RenderMode, ...]
    group: Sequence[int] | None
    #: Whether the modes asked for a direct-only render get one in this job.
    with_direct: bool = True


@dataclass(frozen=True)
class _Run:
    """What every pass of one :func:`_run_jobs` call shares: the plan (with its settings), the
    batch's pass request (seed, samples, progress, prepared geometry) and the data directory."""

    scene: Scene
    plan: _Plan
    request: PassRequest
    data_dir: str | None
    #: One dict mode -> pass output per job, filled by the parts.
    outputs: list[dict[str, PassOutput]]


def _rgb_part(
    run: _Run, rgb_variant: str
) -> tuple[dict[str, np.ndarray], tuple[float, ...], SingleTraversal]:
    """The diagonal modes of every job (one traversal, or the passes) and the AOVs."""
    scene, plan, data_dir = run.scene, run.plan, run.data_dir
    request = replace(run.request, variant=rgb_variant)
    if plan.traversal:
        jobs = [(j.modes, j.group, j.with_direct) for j in plan.jobs]
        parts, single = render_jobs(
            scene, jobs, request, wanted=plan.wanted, data_dir=data_dir, aovs=plan.settings.aovs
        )
        for out, part in zip(run.outputs, parts, strict=True):
            out.update(part)
        return single.aovs, (), single
    for out, job in zip(run.outputs, plan.jobs, strict=True):
        diagonal = [m for m in job.modes if m.kind == "diagonal"]
        if diagonal:  # the passes refuse what they cannot render, even with no value set
            sensors = [get_sensors(m.sensors, data_dir=data_dir) for m in diagonal]
            values = [channel_values(scene, s, data_dir=data_dir) for s in sensors]
            direct = [job.with_direct and m.name in plan.wanted for m in diagonal]
            images = render_diagonal(scene, values, request, direct=direct, active_lights=job.group)
            out.update(zip((m.name for m in diagonal), images, strict=True))
    aov_maps, aov_seconds = render_aovs(scene, request) if plan.settings.aovs else ({}, ())
    return aov_maps, aov_seconds, SingleTraversal({}, ())


def _spectral_part(run: _Run, spectral_variant: str) -> None:
    """The spectral passes of every job (``settings.spectral_batch_spp`` samples each)."""
    batch_spp = run.plan.settings.spectral_batch_spp  # one batch's, as every request holds
    request = replace(run.request, batch_spp=batch_spp, variant=spectral_variant)
    for out, job in zip(run.outputs, run.plan.jobs, strict=True):
        for m in (m for m in job.modes if m.kind == "spectral"):
            out[m.name] = render_spectral(
                run.scene,
                get_sensors(m.sensors, data_dir=run.data_dir),
                request,
                direct=job.with_direct and m.name in run.plan.wanted,
                active_lights=job.group,
                data_dir=run.data_dir,
            )


def _run_jobs(run: _Run) -> tuple[dict[str, np.ndarray], tuple[float, ...], SingleTraversal]:
    """Every pass of the run's jobs into ``run.outputs``, grouped by Mitsuba variant, and the AOVs.

    Each switch between the RGB and the spectral variant reloads Mitsuba's Python modules
    (0.25 s on the 2-core machine, measured: 8 switches were 2.0 s of a 14.5 s default sample),
    so every RGB-variant pass (all diagonal modes of every job, then the AOVs) runs in one
    scope and every spectral pass in another; the variant already active goes first and stays
    active afterwards (``restore=False``), so consecutive batches switch once each, not four
    times. Passes do not depend on each other's order: each sets its own values, seed and spp.
    """
    plan = run.plan
    found: tuple[dict[str, np.ndarray], tuple[float, ...], SingleTraversal]
    found = ({}, (), SingleTraversal({}, ()))
    variant, parts = plan.settings.variant, []
    if plan.settings.aovs or plan.diagonal:
        parts.append(("rgb", choose_variant("rgb", variant)))
    if any(m.kind == "spectral" for job in plan.jobs for m in job.modes):
        parts.append(("spectral", choose_variant("spectral", variant)))
    for kind, chosen in sorted(parts, key=lambda p: p[1] != import_mitsuba().variant()):
        with variant_scope(chosen, restore=False):
            if kind == "rgb":
                found = _rgb_part(run, chosen)
            else:
                _spectral_part(run, chosen)
    return found


def render_meta(
    run: _Run, variants: dict[str, str], timings: dict[str, list[float]]
) -> dict[str, Any]:
    """The ``meta`` record of one batch's render (the run's settings, modes, matrices, seed):
    versions, variants, samples, modes, their sensors and XYZ matrices, the spectral grid,
    which modes have direct light and per-light images, the integrator, and timings (s)."""
    plan, data_dir = run.plan, run.data_dir
    objs, settings = plan.objs, plan.settings
    names = [m.name for m in objs]
    meta = {
        "mitsuba": import_mitsuba().__version__,
        "variants": variants,
        "spp": int(settings.batch_spp),  # one batch's: merge_batches makes it the total
        "seed": int(run.request.seed),
        "max_depth": int(settings.max_depth),
        "modes": names,
        "sensors": {m.name: get_sensors(m.sensors, data_dir=data_dir).name for m in objs},
        "to_xyz": {n: np.asarray(plan.matrices[n]).tolist() for n in names},
        "wavelengths": {
            "start": float(COLORIMETRIC_WAVELENGTHS[0]),
            "end": float(COLORIMETRIC_WAVELENGTHS[-1]),
            "step": float(COLORIMETRIC_WAVELENGTHS[1] - COLORIMETRIC_WAVELENGTHS[0]),
            "unit": "nm",
        },
        "per_light": bool(settings.per_light),
        "direct_modes": sorted(plan.wanted),
        "timings": {k: timing(v) for k, v in timings.items()},
        "units": "XYZ = integral of radiance times CIE 1931 CMF over nm; raw = integral of radiance times S_k",
        "per_light_modes": (
            [m.name for m in plan.share] if plan.split else (names if settings.per_light else [])
        ),
        "integrator": plan.integrator,
    }
    if any(m.kind == "spectral" for m in objs):
        meta["spectral_spp"] = settings.spectral_batch_spp  # one batch's, as "spp" above
    return meta


def render_scene(
    scene: Scene,
    settings: RenderSettings,
    *,
    seed: int,
    progress: PassProgress | None = None,
    data_dir: str | None = None,
) -> RenderResult:
    """Render *scene* in each of ``settings.modes`` and convert every mode to CIE 1931 XYZ.

    One batch: every pass renders ``settings.batch_spp`` samples (a spectral pass
    ``settings.spectral_batch_spp``) with sampler seed *seed*; *progress* is called with 1
    after each Mitsuba pass (:func:`count_passes` gives the total). All diagonal modes share
    one loaded scene and the same paths (Russian roulette off), so ``rgb3``, ``rgb6`` and
    ``bands31`` differ only by spectral error. With ``settings.per_light`` and no
    ``share_mode`` every mode is rendered light by light and ``images`` is exactly the sum of
    the per-light images (and ``direct`` of per-light direct images), costing no extra; the
    ``"single"`` integrator also fills ``RenderResult.transport``.
    """
    plan = _plan(scene, settings, data_dir)
    request = PassRequest.of(settings, seed, progress, prepare_geometry(scene))
    run = _Run(scene, plan, request, data_dir, [{} for _ in plan.jobs])
    aov_maps, aov_seconds, single = _run_jobs(run)
    timings: dict[str, list[float]] = {m.name: [] for m in plan.objs + plan.share}
    variants: dict[str, str] = {}
    for out in run.outputs:
        for name, o in out.items():
            timings[name].extend(o.seconds)
            variants[name] = o.variant
    if settings.aovs:
        timings["aovs"] = list(aov_seconds)
    if single.seconds:
        timings["single"] = list(single.seconds)
    meta = render_meta(run, variants, timings)
    logger.debug("rendered %s: %s", scene.name, {k: sum(v) for k, v in timings.items()})
    return _assemble(run, aov_maps, single, meta)


@dataclass(frozen=True)
class _Plan:
    """What :func:`render_scene` renders: the settings, the modes, their XYZ matrices, the
    jobs, and the integrator, resolved once (:func:`~spectrinsic.render.band_path.traversal.resolve_integrator`).

    ``jobs[:n_main]`` render every mode (all lights, or one light each with ``per_light`` and
    no separate share modes); the rest render the share modes light by light (``split``).
    """

    settings: RenderSettings
    objs: list[RenderMode]
    share: list[RenderMode]
    wanted: set[str]
    #: ``"single"`` or ``"passes"``, as recorded in ``meta["integrator"]``.
    integrator: str
    matrices: dict[str, np.ndarray]
    split: bool
    jobs: list[_Job]
    n_main: int
    #: Whether the RGB part is one band-path traversal (:func:`~spectrinsic.render.band_path.traversal.render_jobs`): the
    #: integrator is ``"single"`` and there are diagonal modes, or a textured scene's AOVs
    #: (which the coverage passes cannot give) without them.
    traversal: bool
    #: Whether any job renders a diagonal mode.
    diagonal: bool


def _plan(scene: Scene, settings: RenderSettings, data_dir: str | None) -> _Plan:
    objs = _modes(settings.modes)
    per_light, per_light_modes = settings.per_light, settings.per_light_modes
    lights = [[j] for j in range(len(scene.lights))]
    split = per_light and per_light_modes is not None
    share = _modes(per_light_modes) if split and per_light_modes is not None else []
    main = [_Job(tuple(objs), g) for g in (lights if per_light and not split else [None])]
    jobs = main + [_Job(tuple(share), g, with_direct=False) for g in lights] if split else main
    integrator = resolve_integrator(settings.integrator, settings.variant)
    diagonal = any(m.kind == "diagonal" for m in objs + share)
    if integrator == "passes" and any(m.glossy for m in scene.materials) and diagonal:
        raise RenderError(
            f"scene {scene.name!r} has glossy materials: diagonal modes render them only with "
            "integrator 'single' on a JIT (LLVM/CUDA) variant; spectral modes render them either way"
        )
    if integrator == "passes" and any(li.kind == "envmap" for li in scene.lights) and diagonal:
        raise RenderError(
            f"scene {scene.name!r} has an environment map: diagonal modes render it only with "
            "integrator 'single' on a JIT (LLVM/CUDA) variant; spectral modes render it either way"
        )
    return _Plan(
        settings=settings,
        objs=objs,
        share=share,
        wanted=_direct_modes(settings.direct, objs),
        integrator=integrator,
        matrices={m.name: to_xyz_matrix(m, scene, data_dir=data_dir) for m in objs},
        split=split,
        jobs=jobs,
        n_main=len(main),
        traversal=integrator == "single" and (diagonal or (settings.aovs and scene.textured)),
        diagonal=diagonal,
    )


def _assemble(
    run: _Run, aov_maps: dict[str, np.ndarray], single: SingleTraversal, meta: dict[str, Any]
) -> RenderResult:
    """The XYZ images of the jobs' raw outputs: totals, per-light shares and direct light."""
    scene, plan, outputs = run.scene, run.plan, run.outputs
    main_out, share_out = outputs[: plan.n_main], outputs[plan.n_main :]
    names = [m.name for m in plan.objs]
    matrices, groups = plan.matrices, [job.group for job in plan.jobs[: plan.n_main]]
    raw = {
        n: np.sum([g[n].image for g in main_out], axis=0, dtype=np.float64).astype(np.float32)
        for n in names
    }
    per_light_images: tuple[dict[str, np.ndarray], ...] = ()
    if plan.split:
        share_xyz = {m.name: to_xyz_matrix(m, scene, data_dir=run.data_dir) for m in plan.share}
        per_light_images = tuple(
            {n: raw_to_xyz(g[n].image, share_xyz[n]) for n in share_xyz} for g in share_out
        )
    elif plan.settings.per_light:
        per_light_images = tuple(
            {n: raw_to_xyz(g[n].image, matrices[n]) for n in names} for g in main_out
        )
    return RenderResult(
        images={n: raw_to_xyz(raw[n], matrices[n]) for n in names},
        raw=raw,
        per_light=per_light_images,
        direct={
            n: raw_to_xyz(
                # every main job renders the direct light of the wanted modes: no None here
                np.sum([g[n].direct for g in main_out], axis=0, dtype=np.float64),  # type: ignore[arg-type]
                matrices[n],
            )
            for n in names
            if n in plan.wanted
        },
        aovs=aov_maps,
        meta=meta,
        transport=single.per_light("transport"),
        parts={p: raw_part for p in PARTS if (raw_part := _part_raw(single, groups, p))},
        part_transport={p: per_light for p in PARTS if (per_light := single.per_light(p))},
    )


def _part_raw(
    single: SingleTraversal,
    groups: Sequence[Sequence[int] | None],
    part: str,
) -> dict[str, np.ndarray]:
    """Mode -> raw channels of a traversal's *part* (one of :data:`~spectrinsic.render.result.PARTS`), summed
    over the main jobs' light *groups* as ``raw`` is; modes without the part are left out."""
    out = {}
    for name, t in single.transport.items():
        parts = [p for g in groups if (p := t.part_image(part, g)) is not None]
        if parts:
            out[name] = np.sum(parts, axis=0, dtype=np.float64).astype(np.float32)
    return out
