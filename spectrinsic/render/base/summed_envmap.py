"""An environment emitter for the spectral variant whose radiance is a sum of grey maps times
spectra: every channel light of every environment map of a scene in one Mitsuba emitter.

A map's channel light j (channel c of the map, emitted spectrum ``E_j``, power included)
radiates ``m_c(ω) · E_j(λ)`` (``spectrinsic/scenes/envmaps.py``). Mitsuba's spectral
``envmap`` cannot carry that (it upsamples RGB non-linearly, ``docs/envmap_design.md``
fact 4) and a scene takes one environment emitter (fact 1), so this emitter, a Python
``mi.Emitter`` that Dr.Jit traces into the kernel, radiates

    L(ω, λ) = Σ_j m_c(j)(R_j⁻¹ ω) · E_j(λ)

with each ``m_c`` evaluated by a Mitsuba ``envmap`` of that channel's grey bitmap, whose
``eval`` is exactly ``m_c · D65_mi(λ)`` (fact 3) and is divided by Mitsuba's ``d65``: the same
bilinear lookup, seam and rotation as the per-channel passes it replaces. ``E_j`` is a
``regular`` spectrum on the 1 nm grid (linearly interpolated).

Directions are sampled from a mixture over the maps: map i with probability ``p_i``, then
Mitsuba's ``envmap`` of the grey map ``Σ_c w_c |m_c|`` (``w_c`` ≥ 0 the channel's weight given,
0 only for a channel the film cannot see), whose pdf is positive wherever a seen channel
radiates; the pdf is ``Σ_i p_i pdf_i(ω)``, the sample weight ``L / pdf``. The estimate is
unbiased for any such weights, so its expectation is the per-channel passes' (only the
variance depends on the weights).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .plugins import regular_spectrum

__all__ = ["MapLight", "summed_envmap"]

#: The largest float32 below 1: a rescaled sample stays in [0, 1) (a Python float, so it also
#: serves the scalar variants, where ``mi.Float`` is ``float``).
_BELOW_ONE = float(np.nextafter(np.float32(1.0), np.float32(0.0)))


@dataclass(frozen=True)
class MapLight:
    """One environment map as the summed emitter takes it: *data* ``(H, W, 3)`` linear RGB
    (float32, the file's), *to_world* its 4 × 4 rotation, and per channel c either ``None``
    (the channel is off) or its emitted spectrum on the wavelengths given (W/(m² sr nm)), at
    least one not ``None``; *weights* ≥ 0 each channel's share of the sampling map (0 only
    where the film sees nothing of the channel's spectrum)."""

    data: np.ndarray
    to_world: np.ndarray
    spectra: tuple[np.ndarray | None, np.ndarray | None, np.ndarray | None]
    weights: tuple[float, float, float]


def _grey(mi: Any, channel: np.ndarray) -> Any:
    """A Mitsuba bitmap whose three channels are *channel* ``(H, W)``: a grey map."""
    grey = np.repeat(np.asarray(channel, np.float32)[..., None], 3, axis=-1)
    return mi.Bitmap(np.ascontiguousarray(grey))


def _envmap(mi: Any, bitmap: Any, to_world: np.ndarray) -> Any:
    return mi.load_dict(
        {
            "type": "envmap",
            "bitmap": bitmap,
            "scale": 1.0,
            "to_world": mi.ScalarTransform4f(np.asarray(to_world, float).tolist()),
        }
    )


def _sampling_map(m: MapLight) -> np.ndarray:
    """The grey map directions of *m* are sampled by: ``Σ_c w_c |m_c|`` over its lit channels."""
    lit = [c for c in range(3) if m.spectra[c] is not None]
    return np.sum([m.weights[c] * np.abs(m.data[..., c]) for c in lit], axis=0, dtype=np.float64)


def _map_probabilities(maps: Sequence[MapLight]) -> np.ndarray:
    """Each map's probability of being sampled: its sampling map's integral over the sphere
    (texels times the solid angle of their row, ``sin θ``), or equal shares if all are dark."""
    power = []
    for m in maps:
        grey = _sampling_map(m)
        rows = grey.shape[0]
        sin_theta = np.sin(np.pi * (np.arange(rows) + 0.5) / rows)
        power.append(float(np.sum(grey * sin_theta[:, None])))
    total = float(np.sum(power))
    if not total > 0:
        return np.full(len(maps), 1.0 / len(maps))
    return np.asarray(power) / total


@dataclass(frozen=True)
class _Parts:
    """What the emitter evaluates with: the active variant's ``mi`` and ``dr``, Mitsuba's
    ``d65``, a (grey envmap, spectrum texture) per lit channel, and each sampled map's grey
    sampling envmap with its probability (> 0)."""

    mi: Any
    dr: Any
    d65: Any
    channels: tuple[tuple[Any, Any], ...]
    samplers: tuple[tuple[float, Any], ...]


def _radiance(parts: _Parts, si: Any, active: Any) -> Any:
    """``Σ_j m_c(j) E_j`` toward ``-si.wi`` at ``si.wavelengths``; 0 where not *active* (the
    path integrator adds ``eval`` unmasked: a masked lane, e.g. of a failed BSDF sample,
    would otherwise get 0 · 1/0)."""
    dr = parts.dr
    d65 = parts.d65.eval(si, active)
    inv_d65 = dr.select(active & (d65 > 0), dr.rcp(d65), 0.0)
    out = dr.zeros(parts.mi.Spectrum)
    for env, spectrum in parts.channels:
        out += env.eval(si, active) * inv_d65 * spectrum.eval(si, active)
    return out


def _toward(parts: _Parts, it: Any, ds: Any) -> Any:
    """A surface interaction looking along ``ds.d`` at *it*'s wavelengths (what ``eval`` takes)."""
    si = parts.dr.zeros(parts.mi.SurfaceInteraction3f)
    si.wi = -ds.d
    si.wavelengths = it.wavelengths
    return si


def _pdf(parts: _Parts, it: Any, ds: Any, active: Any) -> Any:
    """The mixture's solid-angle pdf of ``ds.d``: ``Σ_i p_i pdf_i``."""
    pdf = parts.dr.zeros(parts.mi.Float)
    for p, sampler in parts.samplers:
        pdf += p * sampler.pdf_direction(it, ds, active)
    return pdf


def _sample(parts: _Parts, it: Any, sample: Any, active: Any) -> tuple[Any, Any]:
    """A direction from the mixture (map i where ``sample.x`` falls in its share of [0, 1),
    rescaled) and its weight ``L / pdf``."""
    dr, mi = parts.dr, parts.mi
    ds, start = None, 0.0
    for i, (p, sampler) in enumerate(parts.samplers):
        last = i == len(parts.samplers) - 1
        chosen = (sample.x >= start) & (mi.Bool(True) if last else sample.x < start + p)
        x = dr.clip((sample.x - start) / p, 0.0, _BELOW_ONE)
        ds_i, _ = sampler.sample_direction(it, mi.Point2f(x, sample.y), active & chosen)
        ds = ds_i if ds is None else dr.select(chosen, ds_i, ds)
        start += p
    assert ds is not None  # summed_envmap keeps at least one sampler
    if len(parts.samplers) > 1:
        ds.pdf = _pdf(parts, it, ds, active)
    weight = _radiance(parts, _toward(parts, it, ds), active)
    weight *= dr.select(active & (ds.pdf > 0), dr.rcp(ds.pdf), 0.0)
    return ds, weight


def _emitter_class(mi: Any) -> Any:
    """The summed emitter's class for the active variant (``mi.Emitter`` is per variant)."""

    class SummedEnvmap(mi.Emitter):  # type: ignore[misc, name-defined]
        """Σ_j m_c(j) · E_j over the channel lights of some maps (module docstring)."""

        def __init__(self, parts: _Parts) -> None:
            super().__init__(mi.Properties())
            self.parts = parts
            self.m_flags = mi.EmitterFlags.Infinite | mi.EmitterFlags.SpatiallyVarying

        def eval(self, si: Any, active: Any = True) -> Any:
            return _radiance(self.parts, si, active)

        def eval_direction(self, it: Any, ds: Any, active: Any = True) -> Any:
            return _radiance(self.parts, _toward(self.parts, it, ds), active)

        def pdf_direction(self, it: Any, ds: Any, active: Any = True) -> Any:
            return _pdf(self.parts, it, ds, active)

        def sample_direction(self, it: Any, sample: Any, active: Any = True) -> Any:
            ds, weight = _sample(self.parts, it, sample, active)
            # as Mitsuba's envmap does: the sample names its emitter (a pointer array in JIT
            # variants, the object in scalar ones)
            ds.emitter = mi.EmitterPtr(self) if self.parts.dr.is_jit_v(mi.Float) else self
            return ds, weight

        def attach(self, scene: Any) -> None:
            """Give the inner envmaps the loaded *scene* (its bounding sphere, where they put
            a sampled direction's far point); Mitsuba calls ``set_scene`` on this emitter only."""
            for env, _ in self.parts.channels:
                env.set_scene(scene)
            for _, sampler in self.parts.samplers:
                sampler.set_scene(scene)

        def bbox(self) -> Any:
            return mi.ScalarBoundingBox3f()

        def to_string(self) -> str:
            return f"SummedEnvmap[{len(self.parts.channels)} channels]"

        def _not_for_path(self, *_: Any) -> Any:
            raise NotImplementedError("the summed envmap serves the path integrator only")

        sample_ray = sample_position = pdf_position = sample_wavelengths = _not_for_path

    return SummedEnvmap


def summed_envmap(mi: Any, maps: Sequence[MapLight], wavelengths: np.ndarray) -> Any:
    """The emitter of *maps*' lit channels (module docstring), for the active spectral variant;
    after loading the scene that holds it, call its ``attach(scene)``."""
    channels = [
        (
            _envmap(mi, _grey(mi, m.data[..., c]), m.to_world),
            mi.load_dict(regular_spectrum(spectrum, wavelengths)),
        )
        for m in maps
        for c, spectrum in enumerate(m.spectra)
        if spectrum is not None
    ]
    import drjit as dr

    samplers = tuple(
        (float(p), _envmap(mi, _grey(mi, _sampling_map(m)), m.to_world))
        for m, p in zip(maps, _map_probabilities(maps), strict=True)
        if p > 0  # a map of probability 0 radiates nothing where any channel is seen
    )
    parts = _Parts(mi, dr, mi.load_dict({"type": "d65"}), tuple(channels), samplers)
    return _emitter_class(mi)(parts)
