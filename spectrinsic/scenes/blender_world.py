"""A Blender scene's World as light (issue 42): a constant background as a ``sky``, an
Environment Texture as an environment map (``envmap``).

Cycles lights a scene from its World's shader, which :func:`world_lights` reads (nothing of
the file runs) from the Surface of the World's active output:

- a *Background* node of unlinked Color ``(R, G, B)`` (linear Rec. 709, converted from the
  file's working space, :mod:`~spectrinsic.scenes.blender_working_space`) and Strength ``s``
  is a constant radiance ``s · (R, G, B)`` per channel in W·m⁻²·sr⁻¹ (Strength 1 of white is
  a radiance of 1): one ``sky`` light (Mitsuba ``constant``) whose radiance spectrum is
  ``s · (R b_R + G b_G + B b_B)(λ) · D65(λ)``, D65 at unit luminance and ``b`` the Mallett &
  Yuksel basis: what an environment-map texel of that colour radiates
  (:mod:`~spectrinsic.scenes.envmaps`). With ``m`` the largest of ``s · RGB`` its spectrum is
  ``rgblight:`` of ``s · RGB / m`` and its power ``m · rgb_light_power(s · RGB / m)``
  (:func:`~spectrinsic.spectra.user_spectra.rgb_light_power`);
- a Background whose Color an *Environment Texture* node's Color feeds is an environment map of
  scale ``s``: the node's image (equirectangular, linear, an OpenEXR or Radiance HDR file
  inside the ``.blend``'s folder, ``Non-Color`` only in a Linear Rec.709 file; a packed image
  is refused: unpack it beside the file) looked up at the direction itself (the Vector
  unlinked, or a Texture Coordinate's Generated) or turned by a *Mapping* node about Z alone
  (:func:`blender_map_rotation`).

A World of Strength 0 or a black colour gives no light, and no message. Anything else (a Sky
Texture, a mix, a Light Path, a volume, rays that do not see the World, a Mapping that does
more than turn about Z) is refused in one line naming it; with ``approximate``
(``--approximate``) it is left out, or where something else feeds a Background's Color the
Background's own colour is taken, each said in one phrase.

**Orientation.** Blender looks up its maps, Z up, at ``u = 1/2 − atan2(y, x) / 2π``,
``v = 1 − acos(z) / π`` (Cycles' ``direction_to_equirectangular``; ``v = 1`` the image's top
row); Mitsuba's ``envmap`` looks up its local direction ``ℓ = to_world⁻¹ d`` at
``u = atan2(ℓx, −ℓz) / 2π``, ``v = acos(ℓy) / π`` (``v = 0`` the top row). The two agree
where ``to_world`` takes Mitsuba's local +x, +y, +z to Blender's +Y, +Z, +X
(:data:`BLENDER_MAP_FRAME`). Both read texel columns at ``u = (j + ½) / W``; Blender reads
rows at ``v = (i + ½) / H`` and Mitsuba at ``i / (H − 1)``, so the two place a row up to half
a row apart (``π / 2H``, 0.09° for a 1024-row map; ``docs/envmap_design.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError
from ..spectra.user_spectra import rgb_light_power
from .blender_colours import LINEAR_SPACES
from .blender_working_space import check_raw_values, rec709_colour
from .budget import SceneBudget
from .envmaps import check_map_file, envmap_lights
from .mitsuba_files import file_sha256
from .model import Light

__all__ = [
    "BLENDER_MAP_FRAME",
    "WorldLights",
    "blender_map_rotation",
    "world_lights",
]

#: ``to_world`` (3 x 3, row-major) of a Blender map not turned: Mitsuba's local +x, +y, +z to
#: Blender's +Y, +Z, +X (module docstring).
BLENDER_MAP_FRAME = (
    0.0, 0.0, 1.0,
    1.0, 0.0, 0.0,
    0.0, 1.0, 0.0,
)  # fmt: skip
#: Mapping node types that turn the direction looked up by +angle (the others: ``TEXTURE``,
#: the inverse).
_FORWARD = ("POINT", "VECTOR", "NORMAL")
#: Cycles' ray visibility flags of a World.
_RAYS = ("camera", "diffuse", "glossy", "transmission", "scatter")


@dataclass(frozen=True)
class WorldLights:
    """The lights of a World and the phrases saying what ``approximate`` changed."""

    lights: tuple[Light, ...] = ()
    approximated: tuple[str, ...] = ()


def blender_map_rotation(angle_z: float, *, texture: bool = False) -> tuple[float, ...]:
    """``to_world`` (3 x 3 row-major) of a Blender map behind a Mapping node turning the
    direction looked up by *angle_z* radians about Z: ``Rz(−angle_z) · F`` (types ``POINT``,
    ``VECTOR``, ``NORMAL``: Blender looks up ``Rz(angle_z) d``), or ``Rz(angle_z) · F`` for
    *texture* (type ``TEXTURE``, the inverse), F :data:`BLENDER_MAP_FRAME`.

    >>> [round(x) for x in blender_map_rotation(math.pi / 2)]
    [1, 0, 0, 0, 0, -1, 0, 1, 0]
    """
    theta = angle_z if texture else -angle_z
    c, s = math.cos(theta), math.sin(theta)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    frame = np.asarray(BLENDER_MAP_FRAME).reshape(3, 3)
    return tuple(float(x) for x in (turn @ frame).ravel())


class _Reading:
    """One World read: the refusals' prefix (the file and the World), the approximation
    switch and its phrases (the World alone: the notes name the file,
    :func:`~spectrinsic.scenes.reading_notes.reading_notes`)."""

    def __init__(self, blend: Path, world: str, approximate: bool) -> None:
        self.world = f"world {world!r}"
        self.where = f"{blend}: {self.world}"
        self.approximate = approximate
        self.approximated: list[str] = []

    def refuse_or_say(self, problem: str, instead: str) -> None:
        """Refuse *problem*, or with ``approximate`` record that *instead* was done."""
        if not self.approximate:
            raise SceneError(
                f"{self.where}: {problem}; no exact ground truth (--approximate: {instead})"
            )
        self.approximated.append(f"{self.world}: {problem}: {instead}")


def _label(node: Any) -> str:
    return f"{node.bl_label} node {node.name!r}"


def _source(socket: Any) -> Any:
    """The node feeding *socket* through any reroutes, or None when nothing does."""
    while socket.is_linked:
        link = socket.links[0]
        if link.is_muted:
            return None
        if link.from_node.type != "REROUTE":
            return link
        socket = link.from_node.inputs[0]
    return None


def _value(node: Any, name: str, where: str) -> Any:
    socket = node.inputs[name]
    if socket.is_linked:
        raise SceneError(f"{where}: {_label(node)}'s {name} is linked; expected a value")
    return socket.default_value


def _output(world: Any) -> Any:
    """The World's active output node, or None."""
    outputs = [n for n in world.node_tree.nodes if n.type == "OUTPUT_WORLD" and not n.mute]
    return next((n for n in outputs if n.is_active_output), outputs[0] if outputs else None)


def _background(world: Any, r: _Reading) -> Any:
    """The Background node the World's output shows, or None (no light)."""
    output = _output(world)
    if output is None:
        return None
    volume = _source(output.inputs["Volume"])
    if volume is not None:
        r.refuse_or_say(f"a volume ({_label(volume.from_node)})", "left out")
    link = _source(output.inputs["Surface"])
    if link is None:
        return None
    node = link.from_node
    if node.type != "BACKGROUND" or node.mute:
        r.refuse_or_say(f"its Surface comes from {_label(node)}", "left out")
        return None
    return node


def _colour_sky(name: str, rgb: Any, strength: float, where: str) -> Light | None:
    """The ``sky`` of constant radiance *strength* · *rgb* (module docstring; *rgb* in the
    file's working space, read in linear Rec. 709); None if black."""
    radiance = float(strength) * np.asarray(rec709_colour(rgb, where), dtype=np.float64)
    if not np.isfinite(radiance).all() or (radiance < 0).any():
        raise SceneError(
            f"{where}: background colour {tuple(radiance.tolist())} (colour x strength); "
            "expected finite values >= 0"
        )
    peak = float(radiance.max())
    if peak == 0.0:
        return None
    unit = tuple(float(f"{c:.9g}") for c in radiance / peak)
    spectrum = "rgblight:" + ",".join(f"{c:.9g}" for c in unit)
    return Light("sky", spectrum, peak * rgb_light_power(unit), name=name)  # type: ignore[arg-type]


def _image_file(node: Any, blend: Path, where: str) -> Path:
    """The Environment Texture *node*'s image file, inside the ``.blend``'s folder."""
    image = node.image
    if image is None or image.source != "FILE":
        raise SceneError(f"{where}: {_label(node)} holds no image file")
    if image.packed_file is not None:
        raise SceneError(
            f"{where}: image {image.name!r} is packed in the .blend; unpack it beside the file "
            "(File > External Data > Unpack Resources)"
        )
    if image.library is not None:
        raise SceneError(f"{where}: image {image.name!r} is linked from another .blend")
    space = str(image.colorspace_settings.name)
    if space not in LINEAR_SPACES:
        raise SceneError(
            f"{where}: image {image.name!r} in colour space {space!r}; expected a linear "
            f"radiance map ({', '.join(LINEAR_SPACES)})"
        )
    if space == "Non-Color":
        check_raw_values(f"{where}: image {image.name!r}")
    name = str(image.filepath)  # "//" starts a path relative to the .blend (Blender's rule)
    root = blend.parent.resolve()
    path = (root / name[2:] if name.startswith("//") else Path(name)).resolve()
    if not path.is_relative_to(root):
        raise SceneError(
            f"{where}: image {image.name!r} file {name!r}; expected a file inside the .blend's "
            "folder"
        )
    return path


def _mapping_rotation(mapping: Any, where: str) -> tuple[float, ...]:
    """``to_world`` of a map behind Mapping node *mapping* that turns about Z alone."""
    kind = str(mapping.vector_type)
    rotation = [float(x) for x in _value(mapping, "Rotation", where)]
    scale = [float(x) for x in _value(mapping, "Scale", where)]
    location = mapping.inputs["Location"]
    moved = location.enabled and any(float(x) for x in _value(mapping, "Location", where))
    if rotation[0] or rotation[1] or moved or scale != [1.0, 1.0, 1.0]:
        raise SceneError(
            f"{where}: {_label(mapping)} (type {kind}, rotation {rotation}, scale {scale}) does "
            "more than turn the map about Z; expected rotation X = Y = 0, scale 1, location 0"
        )
    _coordinates(mapping, where)
    return blender_map_rotation(rotation[2], texture=kind not in _FORWARD)


def _coordinates(node: Any, where: str) -> None:
    """Refuse a *node* Vector input other than the direction (a Texture Coordinate's
    Generated: Cycles' world position is the ray's direction)."""
    link = _source(node.inputs["Vector"])
    if link is not None and link.from_node.type == "TEX_COORD":
        if link.from_socket.name == "Generated":
            return
    if link is None and node.type == "TEX_ENVIRONMENT":
        return  # an Environment Texture's own default is the direction
    what = "nothing" if link is None else f"{_label(link.from_node)}"
    raise SceneError(
        f"{where}: {_label(node)}'s Vector comes from {what}; expected the direction (a Texture "
        "Coordinate's Generated, or the Environment Texture's Vector unlinked)"
    )


def _map_rotation(node: Any, where: str) -> tuple[float, ...]:
    """``to_world`` of Environment Texture *node*'s map (module docstring)."""
    link = _source(node.inputs["Vector"])
    if link is not None and link.from_node.type == "MAPPING":
        return _mapping_rotation(link.from_node, where)
    _coordinates(node, where)
    return blender_map_rotation(0.0)


def _environment(
    node: Any, name: str, strength: float, blend: Path, r: _Reading, budget: SceneBudget
) -> tuple[Light, ...]:
    """The three channel lights of Environment Texture *node* at scale *strength*."""
    where = r.where
    if node.mute:
        raise SceneError(f"{where}: {_label(node)} is muted; unmute or remove it")
    if node.projection != "EQUIRECTANGULAR":
        raise SceneError(
            f"{where}: {_label(node)} projection {node.projection!r}; expected EQUIRECTANGULAR"
        )
    if node.interpolation != "Linear":
        r.refuse_or_say(
            f"{_label(node)} interpolation {node.interpolation!r}",
            "read Linear (Mitsuba's bilinear)",
        )
    rotation = _map_rotation(node, where)
    path = _image_file(node, blend, where)
    check_map_file(path, f"{where}: image {node.image.name!r}", budget)
    return envmap_lights(name, str(path), file_sha256(path), strength, rotation)


def _check_lit(world: Any, r: _Reading) -> None:
    """Refuse a World that some rays do not see (the renderer's World is seen by all)."""
    flags = getattr(world, "cycles_visibility", None)
    hidden = [ray for ray in _RAYS if flags is not None and not getattr(flags, ray, True)]
    if hidden:
        r.refuse_or_say(f"ray visibility off for {', '.join(hidden)}", "seen by every ray")


def world_lights(
    world: Any, blend: Path, budget: SceneBudget, *, approximate: bool = False
) -> WorldLights:
    """The lights of Blender World *world* (``bpy.types.World`` or None) of the ``.blend``
    file *blend* (module docstring): none, a ``sky``, or an environment map's three lights.

    Raises
    ------
    SceneError
        One line naming the file, the World and the node that has no exact ground truth
        (unless *approximate*), or a bad value, image file or Mapping.
    """
    if world is None:
        return WorldLights()
    r = _Reading(blend, world.name, approximate)
    if world.node_tree is None:  # a World without nodes: Cycles shows its colour
        sky = _colour_sky(world.name, world.color, 1.0, r.where)
        if sky is not None:
            _check_lit(world, r)
        return WorldLights(() if sky is None else (sky,), tuple(r.approximated))
    background = _background(world, r)
    if background is None:
        return WorldLights((), tuple(r.approximated))
    strength = float(_value(background, "Strength", r.where))
    if not (math.isfinite(strength) and strength >= 0):
        raise SceneError(f"{r.where}: Background strength {strength!r}; expected a number >= 0")
    if strength == 0.0:  # nothing shows, whatever feeds the colour
        return WorldLights((), tuple(r.approximated))
    colour = background.inputs["Color"]
    link = _source(colour)
    if link is None or link.from_node.type != "TEX_ENVIRONMENT" or link.from_socket.name != "Color":
        if link is not None:
            r.refuse_or_say(
                f"its Background's Color comes from {_label(link.from_node)}",
                "the Background's own colour",
            )
        sky = _colour_sky(world.name, colour.default_value, strength, r.where)
        lights: tuple[Light, ...] = () if sky is None else (sky,)
    else:
        lights = _environment(link.from_node, world.name, strength, blend, r, budget)
    if lights:
        _check_lit(world, r)
    return WorldLights(tuple(lights), tuple(r.approximated))
