"""A catalogue of painted objects like those of the MIT intrinsic-images dataset.

Each builder returns one closed :class:`~spectrinsic.scenes.parts.Part` resting on the plane
z = 0, centred on the z axis, sized like the real object (metres, +y away from a viewer in
front). Shape complexity and colour distribution vary on purpose (thesis Figs. 5.6-5.7): a
one-colour animal, striped and banded surfaces of revolution, a patched apple, a printed box
and sheet of paper. Every colour is an exact 1269-matte Munsell chip, so every painted region
has a single known reflectance spectrum.

:data:`OBJECTS` maps each object's name to its builder; all builders take no arguments, so the
catalogue is deterministic.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from .painting import bands, patches, printed, stripes
from .parts import Part, deformed, merge, moved
from .primitives import box, capsule, cone, cylinder, ellipsoid, revolve, sphere, torus

__all__ = ["OBJECTS", "apple", "box_print", "cup", "vase", "frog", "turtle", "paper", "deer"]

_M = "munsell:"


def _rests_on_ground(builder: Callable[[], Part]) -> Callable[[], Part]:
    """Shift the built part vertically so that its lowest point is exactly on z = 0."""

    @functools.wraps(builder)
    def build() -> Part:
        part = builder()
        return moved(part, translate=(0.0, 0.0, -float(part.vertices[:, 2].min())))

    return build


@_rests_on_ground
def apple() -> Part:
    """A red apple with a yellow-green blush and a brown stem (3 colours, smooth, simple)."""
    t = np.linspace(0, np.pi, 19)
    r = 0.04 * np.sin(t) * (1 + 0.08 * np.sin(t))
    z = 0.04 * (1 - np.cos(t)) * 0.95
    # dimples: the axis points sink into the fruit at the top and rise at the bottom
    z[0], z[-1] = 0.006, z[-1] - 0.01
    r[0] = r[-1] = 0.0
    body = revolve(np.stack([r, z], 1), _M + "5R 4/12", sections=32)
    body = patches(body, _M + "2.5GY 7/8", [(0.03, -0.02, 0.05), (0.036, 0.0, 0.035)], 0.022)
    stem = moved(
        cylinder(0.003, 0.022, _M + "5YR 4/4", sections=8),
        rotate_deg=(12, 0, 0),
        translate=(0, 0, 0.074),
    )
    return merge(body, stem)


@_rests_on_ground
def box_print() -> Part:
    """A printed cardboard box: yellow with a red band, a blue logo and dark text lines (4
    colours on flat faces)."""
    part = box((0.12, 0.08, 0.2), _M + "5Y 8/10", center=(0, 0, 0.1), divisions=(12, 8, 20))
    part = bands(part, [None, _M + "5R 5/12", None], axis=2, edges=[0.13, 0.16])
    logo = [
        "............",
        ".BBB....tt..",
        ".B.B........",
        ".BBB.tttttt.",
        "............",
        ".tttttttttt.",
        "............",
        ".tttttt.....",
    ]
    legend = {"B": _M + "5PB 4/10", "t": _M + "5PB 3/2"}
    # front face (-y): columns along x, rows down z
    return printed(
        part, logo, legend, origin=(-0.06, 0.03), cell=0.01, axes=(0, 2), facing=(0, -1, 0)
    )


@_rests_on_ground
def cup() -> Part:
    """A blue mug with a yellow band and a handle: a concave cavity (2 colours)."""
    R, H, wall = 0.04, 0.09, 0.007
    zs = np.linspace(0.0, H, 10)
    outside = [(R * (0.9 + 0.1 * z / H), z) for z in zs]
    inside = [(R * (0.9 + 0.1 * z / H) - wall, z) for z in zs[::-1] if z >= wall]
    profile = [(0.0, 0.0), *outside, *inside, (0.0, wall)]
    body = revolve(profile, _M + "5PB 5/10", sections=32)
    body = bands(body, [None, _M + "5Y 8/12", None], axis=2, edges=[0.05, 0.065])
    # the handle's tube dips into the wall (by 1.5 tube radii < wall), never into the cavity
    major, minor, zh = 0.022, 0.0035, 0.047
    r_wall = R * (0.9 + 0.1 * zh / H)
    handle = moved(
        torus(major, minor, _M + "5PB 5/10", major_sections=16, minor_sections=8),
        rotate_deg=(90, 0, 0),
        translate=(r_wall + major - 0.5 * minor, 0, zh),
    )
    return merge(body, handle)


@_rests_on_ground
def vase() -> Part:
    """A vase with a belly, a narrow neck and a flared lip, painted in 3-colour rings."""
    z = np.linspace(0.0, 0.26, 27)
    r = (
        0.05
        + 0.045 * np.sin(np.pi * np.clip(z / 0.2, 0, 1)) ** 1.5
        - 0.03 * np.clip((z - 0.17) / 0.06, 0, 1)
    )
    r = r + 0.02 * np.clip((z - 0.23) / 0.03, 0, 1)
    wall = 0.006
    inner = [(ri - wall, zi) for ri, zi in zip(r[::-1], z[::-1], strict=True) if zi >= 0.02]
    profile = [(0.0, 0.0), *zip(r, z, strict=True), *inner, (0.0, 0.02)]
    part = revolve(profile, _M + "10R 5/10", sections=36)
    return stripes(
        part, [_M + "10R 5/10", _M + "5Y 8.5/10", _M + "5BG 5/8"], axis=2, width=0.03, offset=0.04
    )


@_rests_on_ground
def frog() -> Part:
    """A sitting frog of ellipsoids: green body with darker spots, yellow eyes, pale belly."""
    green, dark, eye, belly = _M + "5GY 6/8", _M + "5G 4/8", _M + "5Y 8.5/10", _M + "7.5Y 8/6"
    body = moved(
        ellipsoid((0.045, 0.06, 0.03), green, subdivisions=3),
        rotate_deg=(-20, 0, 0),
        translate=(0, 0, 0.035),
    )
    body = patches(
        body, dark, [(0.02, 0.01, 0.06), (-0.025, 0.025, 0.055), (0.0, 0.04, 0.05)], 0.012
    )
    body = bands(body, [belly, None], axis=2, edges=[0.02])
    head = ellipsoid((0.035, 0.03, 0.022), green, center=(0, -0.045, 0.05), subdivisions=2)
    eyes = [sphere(0.009, eye, center=(s * 0.018, -0.05, 0.07), subdivisions=1) for s in (-1, 1)]
    legs = [
        ellipsoid((0.02, 0.035, 0.012), green, center=(s * 0.045, 0.01, 0.012), subdivisions=1)
        for s in (-1, 1)
    ]
    arms = [
        ellipsoid((0.008, 0.008, 0.02), green, center=(s * 0.025, -0.055, 0.018), subdivisions=1)
        for s in (-1, 1)
    ]
    return merge(body, head, *eyes, *legs, *arms)


@_rests_on_ground
def turtle() -> Part:
    """A turtle: a domed brown shell with ochre scute patches, green-grey head, legs, tail."""
    shell_c, scute, skin = _M + "5YR 4/6", _M + "10YR 6/8", _M + "7.5GY 5/6"
    t = np.linspace(0, np.pi / 2, 9)
    dome = [(0.0, 0.0), *[(0.08 * np.cos(a), 0.05 * np.sin(a)) for a in t[:-1]], (0.0, 0.05)]
    shell = moved(
        revolve(dome, shell_c, sections=28), scale=(1.0, 1.25, 1.0), translate=(0, 0, 0.02)
    )
    ring = [
        (0.045 * np.cos(a), 0.055 * np.sin(a), 0.055)
        for a in np.linspace(0, 2 * np.pi, 6, endpoint=False)
    ]
    shell = patches(shell, scute, [(0, 0, 0.07), *ring], 0.017)
    head = ellipsoid((0.02, 0.028, 0.018), skin, center=(0, -0.11, 0.03), subdivisions=2)
    legs = [
        ellipsoid(
            (0.018, 0.022, 0.012), skin, center=(sx * 0.065, sy * 0.07, 0.012), subdivisions=1
        )
        for sx in (-1, 1)
        for sy in (-1, 1)
    ]
    tail = moved(
        cone(0.008, 0.03, skin, sections=8), rotate_deg=(-80, 0, 0), translate=(0, 0.095, 0.02)
    )
    return merge(shell, head, *legs, tail)


@_rests_on_ground
def paper() -> Part:
    """A curled printed page: a thin white sheet with a red heading, a blue picture and grey
    text lines (printed-paper pattern, 4 colours; off-white paper is spectrally flat)."""
    w, h = 0.21, 0.297
    sheet = box((w, h, 0.002), "flat:0.85", center=(0, 0, 0.001), divisions=(42, 60, 1))
    page = [
        ".....................................",
        "..RRRRRRRRRRRRRRRRRRRRRRRRRRRRR......",
        ".....................................",
        "..tttttttttttttttttttttttttttttttt...",
        "..ttttttttttttttttttttttttttttt......",
        "..tttttttttttttttttt.................",
        ".....................................",
        "..BBBBBBBBBBBBBB...tttttttttttttttt..",
        "..BBBBBBBBBBBBBB...tttttttttttttt....",
        "..BBBBBBBBBBBBBB...ttttttttttttttttt.",
        "..BBBBBBBBBBBBBB...tttttttttttt......",
        "..BBBBBBBBBBBBBB.....................",
        ".....................................",
        "..tttttttttttttttttttttttttttttttt...",
        "..ttttttttttttttttttttttttttttttttt..",
        "..tttttttttttttttttttttttt...........",
    ]
    legend = {"R": _M + "5R 5/12", "B": _M + "5B 5/8", "t": _M + "5PB 3/2"}
    cell = w / 37
    sheet = printed(sheet, page, legend, origin=(-w / 2, h / 2 - cell * (len(page) + 1)), cell=cell)

    def curl(v: np.ndarray) -> np.ndarray:
        # the page lies on the ground and curls up towards its far edge
        y = (v[:, 1] + h / 2) / h
        v[:, 2] += 0.04 * y**3 + 0.004 * np.sin(3 * np.pi * v[:, 0] / w) ** 2
        return v

    return deformed(sheet, curl)


@_rests_on_ground
def deer() -> Part:
    """A low-poly deer in one brown (complex shape, single colour)."""
    brown = _M + "5YR 5/6"
    body = moved(
        capsule(0.035, 0.09, brown, sections=14), rotate_deg=(90, 0, 0), translate=(0, 0, 0.13)
    )
    legs = [
        cylinder(0.009, 0.12, brown, center=(sx * 0.022, sy * 0.055, 0.06), sections=8)
        for sx in (-1, 1)
        for sy in (-1, 1)
    ]
    neck = moved(
        capsule(0.016, 0.06, brown, sections=10),
        rotate_deg=(-35, 0, 0),
        translate=(0, -0.075, 0.185),
    )
    head = moved(
        ellipsoid((0.02, 0.04, 0.02), brown, subdivisions=2),
        rotate_deg=(15, 0, 0),
        translate=(0, -0.105, 0.225),
    )
    ears = [
        moved(
            cone(0.01, 0.03, brown, sections=6),
            rotate_deg=(0, s * 40, 0),
            translate=(s * 0.012, -0.09, 0.238),
        )
        for s in (-1, 1)
    ]
    tail = moved(
        cone(0.008, 0.025, brown, sections=6), rotate_deg=(-120, 0, 0), translate=(0, 0.075, 0.15)
    )
    return merge(body, *legs, neck, head, *ears, tail)


#: Builders of the library's objects, by object name.
OBJECTS: dict[str, Callable[[], Part]] = {
    "apple": apple,
    "box": box_print,
    "cup": cup,
    "vase": vase,
    "frog": frog,
    "turtle": turtle,
    "paper": paper,
    "deer": deer,
}
