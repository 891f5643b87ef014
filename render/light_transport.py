"""The per-light band transport of a sample (:class:`LightTransport`) and its algebra: a render
under any other light spectra and powers composed from it (Eq. 1 of :mod:`.transport`,
``raw_k = Σ_l T_lk · ē_lk``). :mod:`.transport` renders it; this module only holds and uses it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from spectrinsic.errors import RenderError
from spectrinsic.render.modes import get_mode, light_spectra, raw_to_xyz, to_xyz_matrix
from spectrinsic.render.result import RenderResult
from spectrinsic.scenes.model import Scene
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS, diagonal_values, get_sensors

__all__ = [
    "LightTransport",
    "ModeLighting",
    "diagonal_mode_names",
    "light_band_means",
    "mode_lighting",
    "relit_result",
    "transport_result",
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
    spp
        Samples per pixel of each batch.
    max_depth
        Longest path of the passes.
    seconds
        Seconds of each Mitsuba pass, per mode, and under ``"single"`` those of the traversals
        carrying every mode at once (empty when read from a file).
    """

    modes: tuple[str, ...]
    sensors: dict[str, str]
    batches: tuple[dict[str, np.ndarray], ...] = field(repr=False)
    seeds: tuple[int, ...]
    spp: int
    max_depth: int
    seconds: dict[str, tuple[float, ...]] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if not self.batches or len(self.batches) != len(self.seeds):
            raise RenderError(f"transport: {len(self.batches)} batches for {len(self.seeds)} seeds")
        shapes = {a.shape[:3] for b in self.batches for a in b.values()}
        if len(shapes) != 1 or any(set(b) != set(self.modes) for b in self.batches):
            raise RenderError(
                f"transport: every batch must hold modes {list(self.modes)} with "
                f"one (lights, height, width); got shapes {sorted(shapes)}"
            )

    @property
    def n_lights(self) -> int:
        """Number of lights L."""
        return int(next(iter(self.batches[0].values())).shape[0])

    @property
    def shape(self) -> tuple[int, int]:
        """``(H, W)`` of the images."""
        first = next(iter(self.batches[0].values()))
        return int(first.shape[1]), int(first.shape[2])


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
    wl = COLORIMETRIC_WAVELENGTHS
    return diagonal_values(
        light_spectra(scene, wl, data_dir=data_dir),
        get_sensors(sensors, data_dir=data_dir).on(wl),
        wl,
    )


@dataclass(frozen=True, eq=False)
class ModeLighting:
    """What a mode's raw channels need from the scene's lights: their band means ``ē_lk``
    (``(L, K)``, :func:`light_band_means`) and the mode's raw -> XYZ matrix (``(3, K)``)."""

    means: np.ndarray
    to_xyz: np.ndarray


def mode_lighting(
    scene: Scene, modes: Iterable[str], *, data_dir: str | None = None
) -> dict[str, ModeLighting]:
    """:class:`ModeLighting` of each of *modes* under *scene*'s lights, computed once for all
    the batches of a sample."""
    return {
        m: ModeLighting(
            light_band_means(scene, get_mode(m).sensors, data_dir=data_dir),
            np.asarray(to_xyz_matrix(get_mode(m), scene, data_dir=data_dir), np.float64),
        )
        for m in modes
    }


def transport_result(
    batch: Mapping[str, np.ndarray],
    scene: Scene,
    *,
    seed: int,
    spp: int,
    meta: Mapping[str, Any] | None = None,
    data_dir: str | None = None,
    lighting: Mapping[str, ModeLighting] | None = None,
) -> RenderResult:
    """The render of one batch under the scene's light spectra and powers, from its transport.

    Per mode: each light's raw channels ``T_l ∘ ē_l`` (float32, as Mitsuba returns a pass),
    their float64 sum as ``raw`` (as :func:`~spectrinsic.render.render_scene` sums per-light
    renders), and the XYZ of both through the mode's matrix for this scene's lights. *meta*
    (a render's metadata) is kept, with the modes, sensors, XYZ matrices, seed and spp set.
    *lighting* (:func:`mode_lighting` of the scene) saves computing it again per batch.
    """
    lighting = lighting or mode_lighting(scene, batch, data_dir=data_dir)
    raw: dict[str, np.ndarray] = {}
    images: dict[str, np.ndarray] = {}
    per_light: list[dict[str, np.ndarray]] = [{} for _ in scene.lights]
    matrices: dict[str, np.ndarray] = {}
    for mode, t in batch.items():
        if t.shape[0] != len(scene.lights):
            raise RenderError(
                f"transport of {mode!r} has {t.shape[0]} lights; the scene has {len(scene.lights)}"
            )
        means = lighting[mode].means
        parts = [
            (np.asarray(t[j], np.float64) * means[j]).astype(np.float32) for j in range(t.shape[0])
        ]
        raw[mode] = np.sum(parts, axis=0, dtype=np.float64).astype(np.float32)
        matrices[mode] = lighting[mode].to_xyz
        images[mode] = raw_to_xyz(raw[mode], matrices[mode])
        for j, part in enumerate(parts):
            per_light[j][mode] = raw_to_xyz(part, matrices[mode])
    out_meta: dict[str, Any] = dict(meta or {})
    out_meta.update(
        seed=int(seed),
        spp=int(spp),
        modes=list(batch),
        per_light=True,
        per_light_modes=list(batch),
        sensors={m: get_mode(m).sensors for m in batch},
        to_xyz={m: np.asarray(v).tolist() for m, v in matrices.items()},
    )
    out_meta.setdefault("timings", {})
    return RenderResult(images=images, raw=raw, per_light=tuple(per_light), meta=out_meta)


def _batch_mean(arrays: Sequence[np.ndarray]) -> np.ndarray:
    """float32 mean of the batches in float64, as :func:`~spectrinsic.render.merge_batches`."""
    return np.mean(np.stack(arrays), axis=0, dtype=np.float64).astype(np.float32)


def relit_result(
    transport: LightTransport,
    scene: Scene,
    *,
    lighting: Mapping[str, ModeLighting],
    meta: Mapping[str, Any] | None = None,
) -> RenderResult:
    """The merged render of every batch of *transport* under *scene*'s lights, with each
    batch's raw channels: bit for bit :func:`~spectrinsic.render.merge_batches` of
    :func:`transport_result` per batch, with every light of a batch composed and converted to
    XYZ in one array operation and the lights' band means and XYZ matrices computed once.
    """
    if transport.n_lights != len(scene.lights):
        raise RenderError(
            f"transport has {transport.n_lights} lights; the scene has {len(scene.lights)}"
        )
    batch_raw: list[dict[str, np.ndarray]] = [{} for _ in transport.batches]
    raw, images = {}, {}
    per_light: list[dict[str, np.ndarray]] = [{} for _ in scene.lights]
    for mode in transport.modes:
        e, to_xyz = lighting[mode].means[:, None, None, :], lighting[mode].to_xyz
        xyz, shares_xyz = [], []
        for b, batch in enumerate(transport.batches):
            shares = (batch[mode].astype(np.float64) * e).astype(np.float32)
            batch_raw[b][mode] = np.sum(shares, axis=0, dtype=np.float64).astype(np.float32)
            xyz.append(raw_to_xyz(batch_raw[b][mode], to_xyz))
            shares_xyz.append(raw_to_xyz(shares, to_xyz))
        raw[mode] = _batch_mean([r[mode] for r in batch_raw])
        images[mode] = _batch_mean(xyz)
        mean_shares = _batch_mean(shares_xyz)
        for j in range(len(scene.lights)):
            per_light[j][mode] = mean_shares[j]
    return RenderResult(
        images=images,
        raw=raw,
        per_light=tuple(per_light),
        meta=_relit_meta(transport, lighting, meta),
        batch_raw=tuple(batch_raw) if len(transport.batches) > 1 else (),
    )


def _relit_meta(
    transport: LightTransport,
    lighting: Mapping[str, ModeLighting],
    meta: Mapping[str, Any] | None,
) -> dict[str, Any]:
    """*meta* with what :func:`transport_result` and a merge of the batches set."""
    n, modes = len(transport.batches), list(transport.modes)
    out: dict[str, Any] = dict(meta or {})
    out.update(
        seed=int(transport.seeds[0]),
        spp=int(transport.spp) * n,
        modes=modes,
        per_light=True,
        per_light_modes=modes,
        sensors={m: get_mode(m).sensors for m in modes},
        to_xyz={m: np.asarray(lighting[m].to_xyz).tolist() for m in modes},
    )
    out.setdefault("timings", {})
    if n > 1:
        out.update(batches=n, batch_spp=int(transport.spp), batch_seeds=list(transport.seeds))
    return out
