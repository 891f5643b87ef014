"""The view rule of generated scenes: a camera is kept only if its view is worth learning from.

Judged when the camera is drawn, before any render, from a low-resolution ray cast
(:data:`VIEW_GRID`² first hits, :class:`spectrinsic.scenes.generators.camera.MeshBoxes`):

* **several materials**: at least :data:`MIN_MATERIALS` materials each cover
  :data:`MIN_MATERIAL_SHARE` of the frame (not a close-up of one surface);
* **no single surface, object or material fills the frame**: no mesh, no object (the meshes of
  one ``object_id``, so an object built of several meshes counts whole) and no material covers
  more than :data:`MAX_SHARE` of it (not one face of one box, not one table top, not 98 % one
  material);
* **enough light reaches the camera**: at least :data:`MIN_LIT_SHARE` of the frame receives
  at least 1/:data:`MAX_CONTRAST` of the irradiance of the frame's bright end, counting the
  lights' direct irradiance (a shadow ray per light, spot cones and one-sided area lights
  respected, the model's radiometry) and one bounce (:data:`BOUNCE_RAYS` cosine-distributed
  rays per point), and the frame's median irradiance is at least :data:`MIN_MEDIAN_LIGHT` of
  the target irradiance the generators give the lights' focus. Rays that leave the scene (a
  missing wall, a window) are dark. A view lit on a small patch only (black once exposed for
  the patch) fails, and so does one looking into the dark. Light that comes in through a
  window (a daylight room's sun and sky) is also spread over the room by its
  interreflections, which one bounce of a few rays misses: the rule adds the split-flux
  estimate ``ρ/(1 − ρ) Φ/A`` (ρ = :data:`BOUNCE_ALBEDO`, Φ the window's flux, A the room's
  surface area; the integrating-sphere law) to every visible point. Rooms without daylight
  have Φ = 0 and are judged as before.

Measured on 50 rooms (root seed 11): 50 of 92 judged cameras pass (acceptance 54 %), about
0.4 s per judged camera on one core (``tests/scenes/generators/test_view_rule.py``).

**The rendered light** (issue 47): the estimate above misses what it does not trace (a sky,
glossy paths, more than one bounce), so where the build gives a probe render
(:data:`FrameProbe`, :func:`spectrinsic.render.probe.probe_luminance`: a
:data:`~spectrinsic.render.probe.PROBE_SIZE`-pixel CIE Y render), a camera that passes is also
judged on it by :func:`judge_frame`: the frame's median luminance must be at least
:data:`MIN_FRAME_MEDIAN` of its 99th percentile. A dark frame around one bright patch fails.
The threshold and its measurement are in ``docs/view_rule.md``.

A camera that fails is re-drawn from the scene's seeded camera generator
(:func:`spectrinsic.scenes.generators.camera.sample_camera`), so a build stays reproducible.
The rule's own bounce rays come from a fixed seed: the same camera always gets the same verdict.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..geometry import camera_rays
from ..library import TARGET_IRRADIANCE
from ..model import Camera, Light, Mesh, Scene
from .camera import MeshBoxes

__all__ = [
    "BOUNCE_RAYS",
    "FRAME_PERCENTILE",
    "FrameJudgement",
    "FrameProbe",
    "MIN_FRAME_MEDIAN",
    "MAX_CONTRAST",
    "MAX_SHARE",
    "MIN_LIT_SHARE",
    "MIN_MATERIALS",
    "VIEW_GRID",
    "ViewJudgement",
    "judge_frame",
    "judge_view",
]

#: Rays per side of the view rule's grid.
VIEW_GRID = 16
#: Most of the frame one mesh or one material may cover (fraction of the grid's rays).
MAX_SHARE = 0.6
#: Materials that must each cover :data:`MIN_MATERIAL_SHARE` of the frame.
MIN_MATERIALS = 3
MIN_MATERIAL_SHARE = 0.02
#: Least fraction of the frame that is lit: receives at least 1/:data:`MAX_CONTRAST` of the
#: irradiance of the frame's bright end (its :data:`BRIGHT_PERCENTILE` th percentile), direct
#: plus one bounce. A view whose light falls on a small patch (the rest black once exposed
#: for the patch) fails; so does one that looks into the dark.
MIN_LIT_SHARE = 0.5
MAX_CONTRAST = 25.0
BRIGHT_PERCENTILE = 95.0
#: Least median irradiance over the frame, as a fraction of the target irradiance the
#: generators give the lights' focus (a view looking into the dark fails).
MIN_MEDIAN_LIGHT = 0.05
#: Bounce rays per visible surface point, and the albedo the bounce is weighted with.
BOUNCE_RAYS = 8
BOUNCE_ALBEDO = 0.5
#: Least median luminance of a probe render, as a fraction of its :data:`FRAME_PERCENTILE` th
#: percentile (``docs/view_rule.md``: measured on the probes of generated rooms).
MIN_FRAME_MEDIAN = 0.01
FRAME_PERCENTILE = 99.0
#: A probe render: the scene (seen from the camera to judge) -> its luminance ``(H, W)``,
#: linear, any unit (only ratios are judged).
FrameProbe = Callable[[Scene], np.ndarray]
#: Offset of secondary rays from a surface (metres).
_EPS = 1e-4


@dataclass(frozen=True)
class ViewJudgement:
    """A camera's verdict and the measurements behind it (shares are fractions of the frame)."""

    max_mesh_share: float
    max_material_share: float
    n_materials: int
    lit_share: float
    #: Share of the frame covered by the largest object (all meshes of one ``object_id``).
    max_object_share: float = 0.0
    #: Median over the frame of the estimated irradiance, relative to the generators' target
    #: irradiance at the lights' focus (``TARGET_IRRADIANCE``).
    median_light: float = 1.0

    @property
    def reasons(self) -> tuple[str, ...]:
        """Why the view fails the rule (empty: it passes)."""
        out = []
        if self.n_materials < MIN_MATERIALS:
            out.append(f"{self.n_materials} materials visible (< {MIN_MATERIALS})")
        if self.max_mesh_share > MAX_SHARE:
            out.append(f"one surface fills {self.max_mesh_share:.0%} of the frame")
        if self.max_object_share > MAX_SHARE:
            out.append(f"one object fills {self.max_object_share:.0%} of the frame")
        if self.max_material_share > MAX_SHARE:
            out.append(f"one material fills {self.max_material_share:.0%} of the frame")
        if self.lit_share < MIN_LIT_SHARE:
            out.append(f"only {self.lit_share:.0%} of the frame is lit")
        if self.median_light < MIN_MEDIAN_LIGHT:
            out.append(f"the frame's median irradiance is {self.median_light:.2g} of the target")
        return tuple(out)

    @property
    def ok(self) -> bool:
        return not self.reasons


@dataclass(frozen=True)
class _Geometry:
    """Every triangle of a scene (:class:`MeshBoxes`, for the culled ray cast) with its mesh,
    material and unit normal."""

    boxes: MeshBoxes
    mesh: np.ndarray
    obj: np.ndarray
    material: np.ndarray
    normal: np.ndarray

    def hits(self, origins: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """First triangle hit by each ray (-1: none) and its distance (inf: none)."""
        return self.boxes.hits(origins, dirs)


def _geometry(meshes: Sequence[Mesh]) -> _Geometry:
    boxes = MeshBoxes.of(meshes)
    tri = boxes.tri
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    return _Geometry(
        boxes=boxes,
        mesh=np.concatenate([np.full(len(m.faces), i) for i, m in enumerate(meshes)]),
        obj=np.concatenate([np.full(len(m.faces), m.object_id) for m in meshes]),
        material=np.concatenate([np.asarray(m.face_materials).reshape(-1) for m in meshes]),
        normal=n,
    )


def _facing(normal: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """Normals turned towards the rays' origins (surfaces are seen from either side)."""
    flip = np.einsum("rk,rk->r", normal, dirs) > 0
    return np.where(flip[:, None], -normal, normal)


def _irradiance_by(g: _Geometry, light: Light, p: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Irradiance *light* gives each point *p* (normal *n*), 0 where occluded: the model's
    radiometry (:func:`spectrinsic.scenes.model.light_power`: ``P / d²`` for point and spot
    lights, ``P A cos θ_light / d²`` for area lights, ``P`` for directional ones) times the cosine
    at the receiver; relative units. A sky counts 0: through a window it lights only what
    the window shows, which this cheap test does not trace (the rule stays conservative)."""
    if light.kind == "sky":
        return np.zeros(len(p))
    if light.kind == "directional":
        to = np.broadcast_to(-np.asarray(light.direction, float), p.shape).copy()
        to /= np.linalg.norm(to, axis=1, keepdims=True)
        dist = np.full(len(p), np.inf)
        facing = np.full(len(p), float(light.power))
    else:
        to = np.asarray(light.position, float) - p
        dist = np.maximum(np.linalg.norm(to, axis=1), 1e-6)
        to /= dist[:, None]
        axis = np.asarray(light.direction, float)
        axis /= max(float(np.linalg.norm(axis)), 1e-12)
        cos_out = -to @ axis  # how far from the light's axis the point lies
        facing = light.power / dist**2
        if light.kind == "spot":
            facing = np.where(cos_out >= math.cos(math.radians(light.cutoff_deg)), facing, 0.0)
        elif light.kind == "area":  # one-sided emitter
            facing = facing * light.size[0] * light.size[1] * np.clip(cos_out, 0.0, None)
        elif light.kind == "sphere":  # a sphere of radiance L subtends π r² / d² (d > r)
            facing = facing * math.pi * light.radius**2
    e = facing * np.clip(np.einsum("rk,rk->r", n, to), 0.0, None)
    idx = np.flatnonzero(e > 0)
    if len(idx):
        _, t = g.hits(p[idx] + _EPS * n[idx], to[idx])
        e[idx[t < dist[idx] - 2 * _EPS]] = 0.0
    return e


def _direct(g: _Geometry, lights: Sequence[Light], p: np.ndarray, n: np.ndarray) -> np.ndarray:
    return sum((_irradiance_by(g, light, p, n) for light in lights), np.zeros(len(p)))


def _bounce_dirs(n: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """:data:`BOUNCE_RAYS` cosine-distributed unit directions about each normal ``(R, B, 3)``."""
    u1, u2 = rng.random((2, len(n), BOUNCE_RAYS))
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    local = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u1)], axis=-1)
    helper = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
    t = np.cross(n, helper)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    b = np.cross(n, t)
    return local[..., :1] * t[:, None] + local[..., 1:2] * b[:, None] + local[..., 2:] * n[:, None]


def _bounce(g: _Geometry, lights: Sequence[Light], p: np.ndarray, n: np.ndarray) -> np.ndarray:
    """One-bounce irradiance at each point: :data:`BOUNCE_ALBEDO` times the mean direct
    irradiance where :data:`BOUNCE_RAYS` cosine-distributed rays land (a Lambertian estimate)."""
    dirs = _bounce_dirs(n, np.random.default_rng(0)).reshape(-1, 3)
    origins = np.repeat(p + _EPS * n, BOUNCE_RAYS, axis=0)
    hit, t = g.hits(origins, dirs)
    e = np.zeros(len(dirs))
    some = hit >= 0
    if some.any():
        q = origins[some] + t[some, None] * dirs[some]
        e[some] = _direct(g, lights, q, _facing(g.normal[hit[some]], dirs[some]))
    return BOUNCE_ALBEDO * e.reshape(len(p), BOUNCE_RAYS).mean(axis=1)


def judge_view(
    meshes: Sequence[Mesh],
    lights: Sequence[Light],
    camera: Camera,
    *,
    flux_density: float = 0.0,
) -> ViewJudgement:
    """The view rule's measurements of *camera* in a scene of *meshes* and *lights*;
    *flux_density* is the flux per unit of enclosure area coming in through openings (Φ/A of
    the module docstring, relative units per m²), 0 when none."""
    g = _geometry(meshes)
    o, d = camera_rays(
        camera.origin,
        camera.target,
        camera.up,
        camera.fov_deg,
        camera.width,
        camera.height,
        n=VIEW_GRID,
    )
    hit, t = g.hits(o, d)
    some = hit >= 0
    total = len(hit)
    meshes_seen = np.bincount(g.mesh[hit[some]], minlength=1)
    materials_seen = np.bincount(g.material[hit[some]], minlength=1)
    objects_seen = np.unique(g.obj[hit[some]], return_counts=True)[1] if some.any() else [0]
    light = np.zeros(total)
    if some.any():
        p = o[some] + t[some, None] * d[some]
        n = _facing(g.normal[hit[some]], d[some])
        ambient = flux_density * BOUNCE_ALBEDO / (1.0 - BOUNCE_ALBEDO)
        light[some] = _direct(g, lights, p, n) + _bounce(g, lights, p, n) + ambient
    bright = float(np.percentile(light, BRIGHT_PERCENTILE))
    lit = light >= bright / MAX_CONTRAST if bright > 0 else np.zeros(total, bool)
    return ViewJudgement(
        max_mesh_share=float(meshes_seen.max()) / total,
        max_material_share=float(materials_seen.max()) / total,
        max_object_share=float(np.max(objects_seen)) / total,
        n_materials=int((materials_seen >= MIN_MATERIAL_SHARE * total).sum()),
        lit_share=float(lit.mean()),
        median_light=float(np.median(light)) / TARGET_IRRADIANCE,
    )


@dataclass(frozen=True)
class FrameJudgement:
    """The rendered light of a view: the frame's median luminance over its
    :data:`FRAME_PERCENTILE` th percentile (0 for a black frame)."""

    median_share: float

    @property
    def reasons(self) -> tuple[str, ...]:
        """Why the frame fails (empty: it passes)."""
        if self.median_share >= MIN_FRAME_MEDIAN:
            return ()
        return (
            f"the rendered frame's median is {self.median_share:.2%} of its "
            f"{FRAME_PERCENTILE:g}th percentile (< {MIN_FRAME_MEDIAN:.0%})",
        )

    @property
    def ok(self) -> bool:
        return not self.reasons


def judge_frame(luminance: np.ndarray) -> FrameJudgement:
    """Judge a rendered frame's light from its linear luminance ``(H, W)`` (every pixel counts:
    one that sees nothing is dark, as in the photograph). Non-finite values count as 0."""
    y = np.nan_to_num(np.asarray(luminance, np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    bright = float(np.percentile(y, FRAME_PERCENTILE))
    return FrameJudgement(median_share=float(np.median(y)) / bright if bright > 0 else 0.0)
