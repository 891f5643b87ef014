"""Mitsuba's ``sunsky`` emitter, approximated (``--approximate``) by a baked sky map and a sun.

Mitsuba 3's ``sunsky`` is a spectral model (Hošek-Wilkie sky, a sun disk of ``sun_aperture``
degrees with limb darkening) with no light-by-light exact counterpart here. Under
``--approximate`` it becomes:

* **the sky**: Mitsuba's own RGB sunsky with the sun off (``sun_scale`` 0), evaluated at the
  nodes of an equirectangular map of :data:`SKY_ROWS` × 2 :data:`SKY_ROWS` texels in the layout
  Mitsuba's ``envmap`` interpolates (column j at u = (j + ½) / W, row i at v = i / (H − 1),
  measured: a one-texel map peaks there), so the map equals the sky at every node and is
  bilinear between, written once to the user cache
  (:func:`sky_map_path`, named by its SHA-256) and read back as an environment map of three
  channel lights (:mod:`~spectrinsic.scenes.envmaps`);
* **the sun**: a ``directional`` light along the sun's direction whose irradiance is the sun
  disk's RGB radiance integrated over the disk (:func:`sun_irradiance`), its spectrum the RGB
  uplift × D65 of an RGB emitter (:func:`~spectrinsic.scenes.mitsuba_spectra.emission`).

So the approximation is the RGB one of Mitsuba's RGB variants (spectra upsampled from RGB), a
point sun for a 0.5° disk, and the map's bilinear interpolation; ``docs/envmap_design.md``
states the error measured against Mitsuba's spectral sunsky.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError
from ..mitsuba_import import import_mitsuba
from .envmaps import envmap_lights
from .mitsuba_spectra import emission
from .mitsuba_tree import XmlNode
from .model import Light

__all__ = ["SKY_ROWS", "sky_map_path", "sun_irradiance", "sunsky_lights"]

#: Rows of the baked sky map (its columns: twice as many).
SKY_ROWS = 128
#: Parameters of ``sunsky`` passed on to Mitsuba for the bake.
_PARAMS = {
    "turbidity", "albedo", "latitude", "longitude", "timezone", "year", "month", "day",
    "hour", "minute", "second", "sun_direction", "sun_scale", "sky_scale", "sun_aperture",
    "complex_sun", "to_world",
}  # fmt: skip
#: The baked map's rotation: its +y (Mitsuba's envmap "up") to the sunsky's +z (its zenith).
_ZENITH_UP = (1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0)
#: Polar x azimuthal quadrature nodes over the sun disk.
_SUN_NODES = (48, 96)


@contextmanager
def _rgb_variant() -> Iterator[Any]:
    """Mitsuba in ``scalar_rgb`` for the block, the caller's variant restored after."""
    mi = import_mitsuba()
    before = mi.variant()
    mi.set_variant("scalar_rgb")
    try:
        yield mi
    finally:
        if before is not None:
            mi.set_variant(before)


def _plugin(mi: Any, node: XmlNode, where: str, **override: float) -> Any:
    """Mitsuba's ``sunsky`` of *node*'s parameters (and *override*)."""
    extra = set(node.props) - _PARAMS
    if extra:
        raise SceneError(f"{where}: unsupported parameter {sorted(extra)[0]!r} in {node.label()}")
    props: dict[str, Any] = {"type": "sunsky"}
    for key, value in node.props.items():
        if key == "to_world":
            props[key] = mi.ScalarTransform4f(np.asarray(value, float).tolist())
        elif isinstance(value, np.ndarray) and value.size == 3:
            props[key] = (
                {"type": "rgb", "value": value.tolist()} if key == "albedo" else value.tolist()
            )
        elif isinstance(value, (int, float, bool)):
            props[key] = value
        else:
            raise SceneError(f"{where}: {key} {value!r} in {node.label()}; expected a number")
    try:
        return mi.load_dict(props | override)
    except RuntimeError as exc:  # Mitsuba's own range checks (turbidity 1-10, albedo 0-1, ...)
        detail = re.sub(r"\[[\w./]+:\d+\]\s*", "", str(exc)).rsplit('"sunsky": ', 1)[-1]
        raise SceneError(
            f"{where}: {node.label()}: {' '.join(detail.split())} (Mitsuba's sunsky refuses it)"
        ) from None


def _eval(mi: Any, emitter: Any, directions: np.ndarray) -> np.ndarray:
    """``(N, 3)`` RGB radiance of *emitter* arriving from world *directions* ``(N, 3)``."""
    si = mi.SurfaceInteraction3f()
    out = np.empty((len(directions), 3))
    for i, d in enumerate(directions):
        si.wi = mi.Vector3f(*(-d))
        out[i] = np.asarray(emitter.eval(si), float)
    return out


def _map_directions(rows: int) -> np.ndarray:
    """``(H, W, 3)`` world directions of the nodes of Mitsuba's envmap (module docstring) in
    its local frame (+y up) turned by :data:`_ZENITH_UP`."""
    cols = 2 * rows
    theta = np.pi * np.arange(rows) / (rows - 1)
    phi = 2 * np.pi * (np.arange(cols) + 0.5) / cols
    t, p = np.meshgrid(theta, phi, indexing="ij")
    local = np.stack([np.sin(t) * np.sin(p), np.cos(t), -np.sin(t) * np.cos(p)], axis=-1)
    return local @ np.reshape(_ZENITH_UP, (3, 3)).T


def sky_map_path(sha256: str) -> Path:
    """Where the baked sky map of content hash *sha256* is kept: the user cache
    (``$XDG_CACHE_HOME``, else ``~/.cache``) under ``spectrinsic/sunsky``."""
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return root / "spectrinsic" / "sunsky" / f"sky-{sha256}.exr"


def _write_map(mi: Any, sky: np.ndarray) -> tuple[str, str]:
    """*sky* ``(H, W, 3)`` written as OpenEXR to :func:`sky_map_path` (a file of that name is
    this program's: its name is its content's hash, and one that does not match is replaced
    only if the program wrote it, i.e. never: it is refused); its path and SHA-256."""
    data = np.ascontiguousarray(sky, np.float32)
    tmp = sky_map_path("tmp").with_name(f"sky-{os.getpid()}.tmp.exr")
    tmp.parent.mkdir(parents=True, exist_ok=True)
    mi.Bitmap(data).write(str(tmp))
    sha = hashlib.sha256(tmp.read_bytes()).hexdigest()
    path = sky_map_path(sha)
    if path.exists() and hashlib.sha256(path.read_bytes()).hexdigest() != sha:
        tmp.unlink()
        raise SceneError(f"{path}: exists with other content; expected the baked sky map")
    os.replace(tmp, path)
    return str(path), sha


def sun_irradiance(mi: Any, sun: Any, direction: np.ndarray, aperture_deg: float) -> np.ndarray:
    """RGB irradiance, at normal incidence, of the sun disk of Mitsuba emitter *sun* (sky off)
    centred on unit *direction*: its radiance integrated over the cap of half-angle
    ``aperture_deg`` / 2 (midpoint rule, :data:`_SUN_NODES`), plus 5 % margin for the limb."""
    half = math.radians(aperture_deg) / 2 * 1.05
    n_t, n_p = _SUN_NODES
    t = (np.arange(n_t) + 0.5) * half / n_t
    p = (np.arange(n_p) + 0.5) * 2 * np.pi / n_p
    tt, pp = np.meshgrid(t, p, indexing="ij")
    d = np.asarray(direction, float)
    u = np.cross(d, [0.0, 0.0, 1.0] if abs(d[2]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(d, u)
    dirs = (
        np.cos(tt)[..., None] * d
        + (np.sin(tt) * np.cos(pp))[..., None] * u
        + (np.sin(tt) * np.sin(pp))[..., None] * v
    )
    radiance = _eval(mi, sun, dirs.reshape(-1, 3)).reshape(n_t, n_p, 3)
    weight = (np.sin(tt) * (half / n_t) * (2 * np.pi / n_p))[..., None]
    return (radiance * weight).sum(axis=(0, 1))


def sunsky_lights(node: XmlNode, where: str, base: Path) -> list[Light]:
    """The approximation of a ``sunsky`` (module docstring): the sky map's three channel
    lights and the sun's ``directional`` light."""
    with _rgb_variant() as mi:
        sky_only = _plugin(mi, node, where, sun_scale=0.0)
        sun_only = _plugin(mi, node, where, sky_scale=0.0)
        direction = np.asarray(mi.traverse(sun_only)["sun_direction"], float).reshape(3)
        direction /= np.linalg.norm(direction)
        aperture = node.number("sun_aperture", 0.5358)
        dirs = _map_directions(SKY_ROWS)
        sky = _eval(mi, sky_only, dirs.reshape(-1, 3)).reshape(*dirs.shape[:2], 3)
        irradiance = sun_irradiance(mi, sun_only, direction, aperture)
        path, sha = _write_map(mi, np.clip(sky, 0.0, None))
    lights = list(envmap_lights("sky", path, sha, 1.0, _ZENITH_UP))
    if irradiance.max() > 0:
        spectrum, power = emission(irradiance, f"{where} sun", base)
        lights.append(
            Light("directional", spectrum, power, direction=tuple(-direction), name="sun")
        )
    return lights
