"""Environment maps: one equirectangular RGB radiance map as three scene lights.

An environment map (Mitsuba ``envmap``, issue 42) is a file of linear RGB radiance over the
sphere of directions. Its spectrum is made linear in the file's channels so every per-light
ground-truth layer stays exact: a texel ``(R, G, B)`` of a map of scale ``s`` radiates

    L(ω, λ) = s · Σ_c m_c(ω) · b_c(λ) · D65(λ)

with ``b_c`` the Mallett & Yuksel (2019) basis (the ``rgb:`` route's and the image textures'),
so ``(1, 1, 1)`` is D65 at unit luminance (``rgblight:1,1,1``). Channel c is one scene
:class:`~spectrinsic.scenes.model.Light` of kind ``envmap``: spectrum ``rgblight:<e_c>``,
power ``s · rgb_light_power(e_c)``, :attr:`~spectrinsic.scenes.model.Light.channel` c, and
the map's file, SHA-256 and rotation. The three are named ``<name>.r``, ``<name>.g`` and
``<name>.b``; :func:`envmap_groups` gathers them back into one map (for the renderer, which
loads the file once, and for people reading shares: the map's share is its three lights').

A scene may hold several maps, whose radiances add (candidates for relighting: set one map's
three lights to a negligible power, ``relight --power``, to swap it for another); no ``sky``
beside a map (Mitsuba takes one environment emitter per scene, ``docs/envmap_design.md``
fact 1; the renderer loads the first map and the band path evaluates the others itself).
"""

from __future__ import annotations

import math
import stat
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError
from ..mitsuba_import import import_mitsuba
from ..spectra.user_spectra import rgb_light_power
from .budget import SceneBudget
from .mitsuba_files import file_sha256
from .model import ENVMAP_CHANNELS, IDENTITY_ROTATION, Light, Scene

__all__ = [
    "MAX_ENVMAP_BYTES",
    "ENVMAP_SPECTRA",
    "EnvMap",
    "envmap_lights",
    "envmap_groups",
    "map_name",
    "check_envmaps",
    "check_map_file",
    "verified_map",
    "portable_map_files",
]

#: Largest environment map file read, in bytes (a 2048 x 1024 float RGB EXR is 24 MiB).
MAX_ENVMAP_BYTES = 64 * 1024 * 1024
#: The spectra of the three channel lights, channel by channel.
ENVMAP_SPECTRA = ("rgblight:1,0,0", "rgblight:0,1,0", "rgblight:0,0,1")
#: First bytes of the formats read: OpenEXR's magic number, Radiance HDR's two headers.
_MAGIC = {"OpenEXR": (b"\x76\x2f\x31\x01",), "Radiance HDR": (b"#?RADIANCE", b"#?RGBE")}


@dataclass(frozen=True)
class EnvMap:
    """One environment map of a scene: its file, SHA-256, rotation and the indices of its
    three channel lights in ``scene.lights`` (channel order)."""

    file: str
    sha256: str
    rotation: tuple[float, ...]
    lights: tuple[int, int, int]


def envmap_lights(
    name: str, file: str, sha256: str, scale: float, rotation: Sequence[float] = IDENTITY_ROTATION
) -> tuple[Light, Light, Light]:
    """The three channel lights of a map of *scale* (module docstring)."""
    rot = tuple(float(x) for x in rotation)
    unit = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    return tuple(  # type: ignore[return-value]
        Light(
            "envmap",
            spectrum,
            float(scale) * rgb_light_power(e),
            name=name + suffix,
            file=file,
            sha256=sha256,
            channel=c,
            rotation=rot,
        )  # fmt: skip
        for c, (spectrum, e, suffix) in enumerate(zip(ENVMAP_SPECTRA, unit, ENVMAP_CHANNELS))
    )


def map_name(light: Light) -> str:
    """The name of the map *light* is a channel of: its name without ``.r``/``.g``/``.b``."""
    suffix = ENVMAP_CHANNELS[light.channel] if 0 <= light.channel < 3 else ""
    return light.name.removesuffix(suffix) if suffix else light.name


def envmap_groups(scene: Scene) -> tuple[EnvMap, ...]:
    """The scene's environment maps (lights of kind ``envmap`` gathered by map name
    (:func:`map_name`), file, SHA-256 and rotation), in the order of their first light. :func:`check_envmaps` makes each complete."""
    groups: dict[tuple[str, str, str, tuple[float, ...]], list[int]] = {}
    for i, light in enumerate(scene.lights):
        if light.kind == "envmap":
            key = (map_name(light), light.file, light.sha256, tuple(light.rotation))
            groups.setdefault(key, []).append(i)
    out = []
    for (_, file, sha, rot), idx in groups.items():
        by_channel = sorted(idx, key=lambda i: scene.lights[i].channel)
        out.append(EnvMap(file, sha, rot, tuple(by_channel)))  # type: ignore[arg-type]
    return tuple(out)


def _rotation_problem(rotation: Sequence[float]) -> str | None:
    r = np.asarray(rotation, float)
    if r.shape != (9,) or not np.isfinite(r).all():
        return f"rotation {tuple(rotation)!r}; expected 9 finite numbers (3 x 3, row-major)"
    m = r.reshape(3, 3)
    if not np.allclose(m @ m.T, np.eye(3), atol=1e-6) or not math.isclose(
        float(np.linalg.det(m)), 1.0, abs_tol=1e-6
    ):
        return "rotation is not a rotation (orthonormal, determinant 1)"
    return None


def check_envmaps(scene: Scene) -> str | None:
    """The first problem of *scene*'s environment maps, or ``None``: each map exactly the three
    channels 0, 1, 2, a rotation, an existing file; no ``sky`` beside a map."""
    groups = envmap_groups(scene)
    if not groups:
        return None
    if any(light.kind == "sky" for light in scene.lights):
        return "an environment map and a sky; Mitsuba takes one environment emitter per scene"
    for env in groups:
        if not env.file:
            return (
                "an envmap light without a map file; environment maps are read from Mitsuba "
                "XML (<emitter type='envmap'>, scenes/FORMAT.md)"
            )
        channels = sorted(scene.lights[i].channel for i in env.lights)
        if channels != [0, 1, 2]:
            return f"environment map {env.file!r} has channel lights {channels}; expected 0, 1, 2"
        problem = _rotation_problem(env.rotation)
        if problem is None and not Path(env.file).is_file():
            problem = f"environment map {env.file!r} not found"
        if problem is not None:
            return problem
    return None


def verified_map(light: Light) -> str:
    """The map file of envmap light *light*, refused in one line if its SHA-256 is no longer
    the one recorded when the scene was read (the ground truth would describe another map)."""
    path = Path(light.file)
    if not path.is_file():
        raise SceneError(f"light {light.name!r}: environment map {light.file!r} not found")
    if light.sha256 and file_sha256(path) != light.sha256:
        raise SceneError(
            f"light {light.name!r}: environment map {light.file!r} changed since the scene was "
            "read (its SHA-256 differs); read the scene again"
        )
    return str(path)


def portable_map_files(record: Mapping[str, Any], base: str | Path | None) -> dict[str, Any]:
    """A copy of scene record *record* (:func:`~spectrinsic.scenes.model.scene_to_dict`) whose
    environment maps' files are named relative to *base*, the scene file's folder (a file
    outside it, or with no folder, by its name alone), as the sample's records name ``csv:``
    files: no written file holds a path of the machine that built it. The map's SHA-256 stays
    beside it."""
    root = Path(base).resolve() if base is not None else None
    lights = []
    for light in record.get("lights", []):
        file = Path(str(light.get("file", "")))
        if light.get("kind") == "envmap" and file.is_absolute():
            inside = root is not None and file.is_relative_to(root)
            rel = file.relative_to(root) if root is not None and inside else Path(file.name)
            light = {**light, "file": rel.as_posix()}
        lights.append(light)
    return {**record, "lights": lights}


def check_map_file(path: Path, what: str, budget: SceneBudget | None = None) -> tuple[int, int]:
    """``(width, height)`` of environment map *path*, checked before it is used: a regular file
    of at most :data:`MAX_ENVMAP_BYTES` in OpenEXR or Radiance HDR format (by its first bytes),
    with three or four channels; its texels charged to *budget*. One line otherwise."""
    try:
        info = path.stat()
    except OSError:
        raise SceneError(f"{what}: {str(path)!r} not found") from None
    if not stat.S_ISREG(info.st_mode):
        raise SceneError(f"{what}: {str(path)!r} is not a regular file")
    if info.st_size > MAX_ENVMAP_BYTES:
        raise SceneError(
            f"{what}: {info.st_size:,} bytes; an environment map holds at most {MAX_ENVMAP_BYTES:,}"
        )
    with path.open("rb") as fh:
        head = fh.read(16)
    if not any(head.startswith(m) for ms in _MAGIC.values() for m in ms):
        raise SceneError(
            f"{what}: {path.name!r} is not an OpenEXR or Radiance HDR file; expected a linear "
            "HDR radiance map (.exr or .hdr)"
        )
    mi = import_mitsuba()
    if mi.variant() is None:  # Bitmap is the same in every variant; one must be set
        mi.set_variant("scalar_rgb")
    try:
        bitmap = mi.Bitmap(str(path))
    except RuntimeError as exc:
        raise SceneError(f"{what}: {path.name!r} unreadable ({str(exc).splitlines()[0]})") from None
    width, height = (int(x) for x in bitmap.size())
    if bitmap.channel_count() not in (3, 4):
        raise SceneError(
            f"{what}: {path.name!r} has {bitmap.channel_count()} channels; expected RGB(A)"
        )
    if budget is not None:
        budget.charge(f"{what} ({path.name}, {width} x {height})", texels=width * height)
    return width, height
