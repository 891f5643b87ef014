"""Relighting for augmentation: random light spectra, relit variants of a build, and an
on-the-fly relighting loader.

Spectra are drawn per light by :func:`spectrinsic.scenes.generators.lights.draw_illuminant`
(the generators' pool: a family drawn uniformly among Planck 2000–10000 K, CIE daylight
4000–10000 K, the CIE LEDs and fluorescents FL1–FL12, then a member), or uniformly from a
pool of names the caller gives; always from an explicit seed.

* ``dataset --relight N`` (:func:`write_relit_variants`): after each sample, N relit sample
  folders ``<sample id>-relit<k>`` (k = 1..N) beside it, seeded by
  ``seed_from_key(sample seed, "relight-<k>")``; each is a complete sample (its own noise,
  denoising and ``meta.json``) in the same split as its source (splits go by scene).
* :class:`RandomRelight`: every layer of a sample relit under fresh random spectra, in memory,
  for ``torch_dataset(..., relight=RandomRelight(seed=0))``; item *i* of epoch *e* gets the
  spectra of ``default_rng([seed, e, i])``, the same on every worker.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...rng import seed_from_key
from ...scenes.generators.lights import draw_illuminant
from ..layers import compute_ground_truth
from ..sample.integrity import sample_problem
from ..sample.meta import read_meta
from . import relight, relit_render, settings_of

__all__ = [
    "RELIT_TAG",
    "draw_light_spectra",
    "relit_variant_id",
    "write_relit_variants",
    "relit_problem",
    "relit_layers",
    "RandomRelight",
]

#: Separator between a sample id and the relit variant's number.
RELIT_TAG = "-relit"


def draw_light_spectra(
    n_lights: int, rng: np.random.Generator, pool: Sequence[str] | None = None
) -> dict[int, str]:
    """``{light index: illuminant name}`` for *n_lights* lights, drawn with *rng* from *pool*
    (uniformly) or, without one, from the generators' illuminant families."""
    if pool is not None and not pool:
        raise DatasetError("relight pool: expected at least one illuminant name")
    if pool:
        return {i: str(pool[int(rng.integers(len(pool)))]) for i in range(n_lights)}
    return {i: draw_illuminant(rng) for i in range(n_lights)}


def relit_variant_id(sample_id: str, k: int) -> str:
    """Folder name of relit variant *k* (1-based) of *sample_id*.

    >>> relit_variant_id("room-living__v0__white", 2)
    'room-living__v0__white-relit2'
    """
    return f"{sample_id}{RELIT_TAG}{int(k)}"


def _variant_lights(n_lights: int, k: int, seed: int) -> dict[int, str]:
    rng = np.random.default_rng(seed_from_key(int(seed), f"relight-{k}"))
    return draw_light_spectra(n_lights, rng)


def write_relit_variants(
    sample_dir: str | os.PathLike[str],
    n: int,
    *,
    seed: int,
    data_dir: Any = None,
    scene_dir: str | os.PathLike[str] | None = None,
) -> list[Path]:
    """Write *n* relit variants of a sample that stores its transport, beside it (*scene_dir*:
    the scene file's folder, for a sample with ``csv:`` spectra)."""
    sample = Path(sample_dir)
    n_lights = len(read_meta(sample).lights)
    return [
        relight(
            sample,
            _variant_lights(n_lights, k, seed),
            sample.parent / relit_variant_id(sample.name, k),
            data_dir=data_dir,
            scene_dir=scene_dir,
        )
        for k in range(1, int(n) + 1)
    ]


def relit_problem(sample_dir: str | os.PathLike[str], n: int, config_hash: str) -> str | None:
    """Why the *n* relit variants of a sample are not all complete and intact, or ``None``."""
    sample = Path(sample_dir)
    for k in range(1, int(n) + 1):
        variant = sample.parent / relit_variant_id(sample.name, k)
        problem = sample_problem(variant, config_hash)
        if problem is not None:
            return f"relit variant {variant.name}: {problem}"
    return None


def relit_layers(
    sample_dir: str | os.PathLike[str],
    lights: Mapping[int, str],
    *,
    powers: Mapping[int, float] | None = None,
    data_dir: Any = None,
    denoise: bool | None = None,
    cameras: bool = True,
    scene_dir: str | os.PathLike[str] | None = None,
) -> dict[str, Any]:
    """Every layer of a sample under new light spectra, in memory, keyed as
    :func:`~spectrinsic.gt_export.dataset.loader.load_sample` returns them (``mask`` bool, ids int32
    under ``ids``, ``meta`` the source's ``meta.json`` with the new ``lights`` spectra).

    By default the layers are those the sample has, exactly as :func:`~spectrinsic.gt_export.relight.relight`
    writes them. For cheaper augmentation, ``denoise=False`` leaves out OIDN (the denoised
    layers then come from the raw irradiance, as in a ``--no-denoise`` build; about half the
    time at 256²) and ``cameras=False`` the camera layers. *scene_dir*: the scene file's
    folder, for a sample with ``csv:`` spectra (:func:`~spectrinsic.gt_export.relight.relit_render`).
    """
    relit = relit_render(sample_dir, lights, powers=powers, data_dir=data_dir, scene_dir=scene_dir)
    meta = relit.meta
    settings = settings_of(meta, None if data_dir is None else str(data_dir), scene_dir)
    settings = replace(  # cameras off: no camera layers, and no chain's camera added back
        settings,
        cameras=settings.cameras if cameras else (),
        camera=settings.camera if cameras else None,
        denoise=settings.denoise if denoise is None else denoise,
    )
    gt = compute_ground_truth(relit.scene, relit.result, settings)
    out: dict[str, Any] = {name: layer.data for name, layer in gt.layers.items()}
    if "mask" in out:
        out["mask"] = out["mask"] > 0.5
    ids = {}
    for key in ("material_id", "object_id", "semantic"):
        if key in out:
            out[key] = np.rint(out[key]).astype(np.int32)
            ids[key.removesuffix("_id")] = out[key]
    out["ids"] = ids
    new_meta = dict(meta)
    new_meta["lights"] = [
        {
            "index": r.index,
            "spectrum": r.spectrum,
            "power": r.power,
            "share": r.share,
            "xy": r.xy,
            "srgb": r.srgb,
        }
        for r in gt.lights
    ]
    new_meta["relit"] = relit.result.meta["relit"]
    out["meta"] = new_meta
    return out


@dataclass(frozen=True)
class RandomRelight:
    """On-the-fly relighting for a loader: each call relights a sample under random spectra.

    Attributes
    ----------
    seed
        Root seed; the spectra of item *index* in *epoch* come from ``default_rng([seed,
        epoch, index])``.
    pool
        Illuminant names to draw from uniformly; ``None``: the generators' families.
    data_dir
        Spectral data directory, for ``sfu:`` names.
    denoise, cameras
        As :func:`relit_layers`: ``None``/``True`` keep the sample's layers exactly;
        ``denoise=False`` and ``cameras=False`` trade them for speed.
    scene_dir
        The folder of the scene files the samples were built from, for samples with ``csv:``
        spectra (named relative to it; :func:`relit_layers`).
    """

    seed: int
    pool: tuple[str, ...] | None = None
    data_dir: str | None = None
    denoise: bool | None = None
    cameras: bool = True
    scene_dir: str | None = None

    def lights(self, n_lights: int, index: int, epoch: int = 0) -> dict[int, str]:
        """The spectra item *index* gets in *epoch*."""
        rng = np.random.default_rng([int(self.seed), int(epoch), int(index)])
        return draw_light_spectra(n_lights, rng, self.pool)

    def __call__(
        self, sample_dir: str | os.PathLike[str], index: int, epoch: int = 0
    ) -> dict[str, Any]:
        """Every layer of the sample in *sample_dir* under this item's random spectra."""
        lights = self.lights(len(read_meta(sample_dir).lights), index, epoch)
        return relit_layers(
            sample_dir,
            lights,
            data_dir=self.data_dir,
            denoise=self.denoise,
            cameras=self.cameras,
            scene_dir=self.scene_dir,
        )
