"""The per-light band transport of a sample (:class:`LightTransport`) and its algebra: a render
under any other light spectra and powers composed from it (Eq. 1 of :mod:`.transport`,
``raw_k = Σ_l T_lk · ē_lk``). :mod:`.transport` renders it; this module only holds and uses it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from spectrinsic.errors import RenderError
from spectrinsic.render.modes import get_mode, light_spectra, raw_to_xyz, to_xyz_matrix
from spectrinsic.render.result import RenderResult
from spectrinsic.scenes.model import Scene
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS, diagonal_values, get_sensors

__all__ = ["LightTransport", "diagonal_mode_names", "light_band_means", "transport_result"]


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


def transport_result(
    batch: Mapping[str, np.ndarray],
    scene: Scene,
    *,
    seed: int,
    spp: int,
    meta: Mapping[str, Any] | None = None,
    data_dir: str | None = None,
) -> RenderResult:
    """The render of one batch under the scene's light spectra and powers, from its transport.

    Per mode: each light's raw channels ``T_l ∘ ē_l`` (float32, as Mitsuba returns a pass),
    their float64 sum as ``raw`` (as :func:`~spectrinsic.render.render_scene` sums per-light
    renders), and the XYZ of both through the mode's matrix for this scene's lights. *meta*
    (a render's metadata) is kept, with the modes, sensors, XYZ matrices, seed and spp set.
    """
    raw: dict[str, np.ndarray] = {}
    images: dict[str, np.ndarray] = {}
    per_light: list[dict[str, np.ndarray]] = [{} for _ in scene.lights]
    matrices: dict[str, np.ndarray] = {}
    for mode, t in batch.items():
        if t.shape[0] != len(scene.lights):
            raise RenderError(
                f"transport of {mode!r} has {t.shape[0]} lights; the scene has {len(scene.lights)}"
            )
        means = light_band_means(scene, get_mode(mode).sensors, data_dir=data_dir)
        parts = [
            (np.asarray(t[j], np.float64) * means[j]).astype(np.float32) for j in range(t.shape[0])
        ]
        raw[mode] = np.sum(parts, axis=0, dtype=np.float64).astype(np.float32)
        matrices[mode] = to_xyz_matrix(get_mode(mode), scene, data_dir=data_dir)
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
