"""The per-light band transport of a sample (:class:`LightTransport`) and its algebra: a render
under any other light spectra and powers composed from it (Eq. 1 of :mod:`~spectrinsic.render.transport_render`,
``raw_k = Σ_l T_lk · ē_lk``). :mod:`~spectrinsic.render.transport_render` renders it; this module only holds and uses it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import RenderError
from ...scenes.model import Scene
from ...spectra import COLORIMETRIC_WAVELENGTHS, diagonal_values, get_sensors
from ...threads import thread_map
from ..result import RenderResult
from .batch_means import batch_counts, batch_mean
from .modes import get_mode, light_spectra, raw_to_xyz, to_xyz_matrix
from .shares import compose, light_shares, sum_lights

__all__ = [
    "LightTransport",
    "diagonal_mode_names",
    "light_band_means",
    "relit_result",
]


@dataclass(frozen=True, eq=False)
class LightTransport:
    """The per-light transport of one scene view, batch by batch (Eq. 1 of the module).

    Attributes
    ----------
    modes
        Diagonal render modes held (``"rgb3"``, ``"rgb6"``, ``"bands31"``).
    sensors
        mode -> registry name of its sensor set (channel k of the arrays is sensor k).
    batches
        One dict per independent batch: mode -> ``(L, H, W, K)`` float32 ``T_lk``, the raw
        channels light l gives alone with the flat unit spectrum at power 1 (render units).
    seeds
        Sampler seed of each batch.
    batch_spp
        Samples per pixel of each batch (the total is ``batch_spp * len(batches)``).
    max_depth
        Longest path of the passes.
    seconds
        Seconds of each Mitsuba pass, per mode, and under ``"single"`` those of the traversals
        carrying every mode at once (empty when read from a file).
    parts
        :data:`~spectrinsic.render.result.PARTS` name -> one dict per batch as :attr:`batches`,
        for the same unit spectrum; only the parts held.
    """

    modes: tuple[str, ...]
    sensors: dict[str, str]
    batches: tuple[dict[str, np.ndarray], ...] = field(repr=False)
    seeds: tuple[int, ...]
    batch_spp: int
    max_depth: int
    seconds: dict[str, tuple[float, ...]] = field(default_factory=dict, repr=False)
    parts: dict[str, tuple[dict[str, np.ndarray], ...]] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if not self.batches or len(self.batches) != len(self.seeds):
            raise RenderError(f"transport: {len(self.batches)} batches for {len(self.seeds)} seeds")
        held = [self.batches, *(p for p in self.parts.values() if p)]
        shapes = {a.shape[:3] for part in held for b in part for a in b.values()}
        if (
            len(shapes) != 1
            or any(len(part) != len(self.batches) for part in held)
            or any(set(b) != set(self.modes) for part in held for b in part)
        ):
            raise RenderError(
                f"transport: every batch must hold modes {list(self.modes)} with "
                f"one (lights, height, width); got shapes {sorted(shapes)}"
            )

    @property
    def n_lights(self) -> int:
        """Number of lights L."""
        return int(next(iter(self.batches[0].values())).shape[0])


def diagonal_mode_names(modes: Iterable[str]) -> tuple[str, ...]:
    """The diagonal (relightable) modes among *modes*, in order, validated."""
    return tuple(m for m in dict.fromkeys(modes) if get_mode(m).kind == "diagonal")


def light_band_means(scene: Scene, sensors: str, *, data_dir: str | None = None) -> np.ndarray:
    """``(L, K)`` float64 ``ē_lk = power_l ∫L_l S_k dλ / ∫S_k dλ`` of the scene's lights
    (Eq. 1), on the 1 nm CIE grid; the flat unit spectrum gives 1 in every channel.

    >>> from spectrinsic.scenes.model import Camera, Light, Scene
    >>> lamp = Light("point", "flat:1", 2.0)
    >>> s = Scene("s", (), (), (lamp,), Camera((0, 0, 1), (0, 0, 0)))
    >>> float(light_band_means(s, "bands:31@400-700").round(12).max())
    2.0
    """
    emitted = light_spectra(scene, data_dir=data_dir)
    return _band_means(emitted, sensors, data_dir)


def _band_means(emitted: np.ndarray, sensors: str, data_dir: str | None) -> np.ndarray:
    wl = COLORIMETRIC_WAVELENGTHS
    return diagonal_values(emitted, get_sensors(sensors, data_dir=data_dir).on(wl), wl)


@dataclass(frozen=True, eq=False)
class _ModeLighting:
    """What a mode's raw channels need from the scene's lights: their band means ``ē_lk``
    (``(L, K)``, :func:`light_band_means`) and the mode's raw -> XYZ matrix (``(3, K)``)."""

    means: np.ndarray
    to_xyz: np.ndarray


def _mode_lighting(
    scene: Scene, modes: Iterable[str], *, data_dir: str | None = None
) -> dict[str, _ModeLighting]:
    """:class:`_ModeLighting` of each of *modes* under *scene*'s lights, computed once for all
    the batches of a sample (the lights' spectra resampled once for all modes)."""
    emitted = light_spectra(scene, data_dir=data_dir)
    return {
        m: _ModeLighting(
            _band_means(emitted, get_mode(m).sensors, data_dir),
            to_xyz_matrix(get_mode(m), scene, data_dir=data_dir, emitted=emitted),
        )
        for m in modes
    }


@dataclass(frozen=True, eq=False)
class _BatchImages:
    """One batch of one mode under the new lights: raw channels, their XYZ, each light's XYZ."""

    raw: np.ndarray
    xyz: np.ndarray
    shares_xyz: np.ndarray


def _batch_images(transport: np.ndarray, lighting: _ModeLighting) -> _BatchImages:
    """Eq. 1 for one batch of one mode: ``(L, H, W, K)`` *transport* under *lighting*. The
    image's XYZ is the float64 sum of the lights' XYZ (the matrix is linear), which spares
    converting the summed raw channels a second time."""
    shares = light_shares(transport, lighting.means)
    each = raw_to_xyz(shares, lighting.to_xyz, np.float64)
    return _BatchImages(
        sum_lights(shares), each.sum(axis=0).astype(np.float32), each.astype(np.float32)
    )


def _meta(
    transport: LightTransport,
    lighting: Mapping[str, _ModeLighting],
    meta: Mapping[str, Any] | None,
) -> dict[str, Any]:
    """*meta* (a render's metadata) with the modes, sensors, XYZ matrices and the batches'
    counts (:func:`~.batch_means.batch_counts`) set."""
    modes = list(transport.modes)
    out: dict[str, Any] = dict(meta or {})
    out.update(
        batch_counts(transport.seeds, int(transport.batch_spp)),
        modes=modes,
        per_light=True,
        per_light_modes=modes,
        sensors={m: get_mode(m).sensors for m in modes},
        to_xyz={m: np.asarray(lighting[m].to_xyz).tolist() for m in modes},
    )
    out.setdefault("timings", {})
    return out


def relit_result(
    transport: LightTransport,
    scene: Scene,
    *,
    meta: Mapping[str, Any] | None = None,
    data_dir: str | None = None,
) -> RenderResult:
    """The render of every batch of *transport* under *scene*'s light spectra and powers
    (Eq. 1), merged as :func:`~spectrinsic.render.merge_batches` merges rendered batches, bit
    for bit (each batch's raw channels kept).

    Per mode and batch: each light's raw channels ``T_l ∘ ē_l`` (float32, as Mitsuba returns a
    pass), their float64 sum as ``raw`` (as :func:`~spectrinsic.render.render_scene` sums
    lights), and the XYZ of both through the mode's matrix for this scene's lights; the parts
    likewise, where held. *meta* (a render's metadata) is kept, with the modes, sensors, XYZ
    matrices, seeds and spp set. The batches and modes are independent, so they run side by
    side (:func:`~spectrinsic.threads.thread_map`).
    """
    if transport.n_lights != len(scene.lights):
        raise RenderError(
            f"transport has {transport.n_lights} lights; the scene has {len(scene.lights)}"
        )
    lighting = _mode_lighting(scene, transport.modes, data_dir=data_dir)
    n = len(transport.batches)
    tasks = [(m, b) for m in transport.modes for b in range(n)]
    composed = thread_map(
        lambda t: _batch_images(transport.batches[t[1]][t[0]], lighting[t[0]]), tasks
    )
    done = dict(zip(tasks, composed))
    raw: dict[str, np.ndarray] = {}
    images: dict[str, np.ndarray] = {}
    parts: dict[str, dict[str, np.ndarray]] = {p: {} for p, held in transport.parts.items() if held}
    per_light: list[dict[str, np.ndarray]] = [{} for _ in scene.lights]
    for mode in transport.modes:
        mine = [done[mode, b] for b in range(n)]
        raw[mode] = batch_mean([c.raw for c in mine])
        images[mode] = batch_mean([c.xyz for c in mine])
        mean_shares = batch_mean([c.shares_xyz for c in mine])
        for j in range(len(scene.lights)):
            per_light[j][mode] = mean_shares[j]
        e = lighting[mode].means
        for p, out in parts.items():
            out[mode] = batch_mean([compose(b[mode], e) for b in transport.parts[p]])
    return RenderResult(
        images=images,
        raw=raw,
        per_light=tuple(per_light),
        meta=_meta(transport, lighting, meta),
        batch_raw=tuple({m: done[m, b].raw for m in transport.modes} for b in range(n))
        if n > 1
        else (),
        parts=parts,
    )
