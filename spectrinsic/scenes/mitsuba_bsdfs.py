"""Mitsuba XML BSDFs as :class:`~spectrinsic.scenes.model.Material` records.

Read exactly: ``diffuse`` (``reflectance``), ``plastic`` and ``roughplastic``
(``diffuse_reflectance``, numeric ``int_ior``/``ext_ior``, Mitsuba's defaults 1.49 and air's
1.000277), ``conductor`` and ``roughconductor`` (``material``, one of Mitsuba's measured
metals), the rough ones with ``alpha`` and the ``ggx`` distribution (Mitsuba's default,
``beckmann``, is refused: the renderer's microfacets are GGX), bare or in a ``twosided`` with one BSDF (or two equal
ones). A conductor's ``specular_reflectance`` (``rgb``, ``spectrum``, ``float``) is read as
its reflection tint, exactly (the band path multiplies its band Fresnel by it); a plastic's
other than 1 has no exact counterpart and is refused. A
``conductor`` with ``material`` ``none`` (or none given, Mitsuba's default) is the perfect mirror.

Glass (:data:`GLASS`) is read exactly: ``dielectric``, ``thindielectric`` and
``roughdielectric`` (``alpha``, ``ggx`` only, as above) with ``int_ior``/``ext_ior`` numbers or
the names of Mitsuba's own table (``bk7``, ``water``, ``air``..., Mitsuba's defaults ``bk7`` and
``air``), whose ratio is the material's ``ior``. A ``specular_transmittance`` other than 1 is
tinted glass: its ``rgb``, ``spectrum`` or ``float`` becomes the material's ``transmittance``
(as a reflectance above; Mitsuba multiplies only the refracted lobe by it, and so does the band
path), and a ``specular_reflectance`` other than 1 its ``specular_reflectance`` (Mitsuba and
the band path multiply only the reflected lobe by it). A textured tint (``bitmap``) is refused
(``--approximate``: taken as 1).

The wrappers ``mask``, ``bumpmap`` and ``normalmap`` (:data:`WRAPPERS`, in any order with
``twosided``) are read exactly: the material is the BSDF they wrap, and the wrappers' opacity
and bump or normal map become the mesh's
:class:`~spectrinsic.scenes.surface_maps.MeshMaps` (:mod:`~spectrinsic.scenes.mitsuba_maps`).

Without exact ground truth: ``bitmap`` textures anywhere but a matte ``diffuse`` reflectance
(that one is an exact image texture, :mod:`~spectrinsic.scenes.mitsuba_bitmaps`), refused in one
line naming it; under ``--approximate`` a bitmap becomes Mitsuba's default 0.5 grey, said in one
line.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..errors import SceneError
from ..spectra.conductors import PERFECT_MIRROR
from .materials import METAL_SPECTRUM
from .mitsuba_spectra import reflectance_name
from .mitsuba_tree import Value, XmlNode, named_ior
from .model import GLASS_TINTS, Material, MaterialKind

__all__ = ["GLASS", "WRAPPERS", "DEFAULT_MATERIAL", "inner_bsdf", "material_of"]

#: Transmissive BSDFs, read as clear glass.
GLASS = ("dielectric", "thindielectric", "roughdielectric")
#: BSDFs wrapping another: the material is the inner one, the wrapper a mesh's map
#: (:mod:`~spectrinsic.scenes.mitsuba_maps`).
WRAPPERS = ("mask", "bumpmap", "normalmap")
#: Mitsuba's BSDF of a shape that names none: diffuse 0.5.
DEFAULT_MATERIAL = Material("flat:0.5", "flat:0.5")

_PARAMS = {
    "diffuse": {"reflectance"},
    "plastic": {"diffuse_reflectance", "specular_reflectance", "int_ior", "ext_ior"},
    "conductor": {"material", "specular_reflectance"},
}
_PARAMS["dielectric"] = {"int_ior", "ext_ior", "specular_reflectance", "specular_transmittance"}
_PARAMS["thindielectric"] = _PARAMS["dielectric"]
_PARAMS["roughplastic"] = _PARAMS["plastic"] | {"alpha", "distribution", "sample_visible"}
_PARAMS["roughconductor"] = _PARAMS["conductor"] | {"alpha", "distribution", "sample_visible"}
_PARAMS["roughdielectric"] = _PARAMS["dielectric"] | {"alpha", "distribution", "sample_visible"}
#: Mitsuba's default indices of a dielectric's inside and outside (its ``ior.h`` names).
_GLASS_IORS = ("bk7", "air")

#: ``say(phrase)`` records an approximation; ``None`` where approximations are refused.
Say = Callable[[str], None] | None


def _number(node: XmlNode, key: str, default: float, what: str) -> float:
    value = node.props.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(f"{what}: {key} {value!r} in {node.label()}; expected a number")
    return float(value)


def _unsupported(node: XmlNode, what: str, say: Say, instead: str) -> None:
    if say is None:
        raise SceneError(
            f"{what}: {node.label()} has no exact ground truth yet; refused "
            f"(--approximate: {instead})"
        )
    say(f"{what}: {node.label()} {instead}")


def _colour(node: XmlNode, key: str, what: str, base: Path, say: Say) -> str:
    value: Value | None = node.props.get(key)
    if isinstance(value, XmlNode) and value.plugin == "bitmap":
        _unsupported(value, f"{what} {key}", say, "replaced by a uniform 0.5 reflectance")
        return "flat:0.5"
    return reflectance_name(value, f"{what} {key}", base)


def _unit_specular(node: XmlNode, what: str, say: Say, key: str = "specular_reflectance") -> None:
    value = node.props.get(key, 1.0)
    unit = isinstance(value, (int, float)) and value == 1.0
    unit = unit or (isinstance(value, np.ndarray) and bool(np.all(value == 1.0)))
    if not unit:
        shown = value.tolist() if isinstance(value, np.ndarray) else value
        if say is None:
            raise SceneError(
                f"{what}: {key} {shown!r} in {node.label()}; only 1 has exact "
                "ground truth (--approximate would use 1)"
            )
        say(f"{what}: {node.label()} {key} {shown!r} taken as 1")


def inner_bsdf(node: XmlNode, what: str) -> XmlNode:
    """The one BSDF a ``twosided`` or a wrapper *node* holds (two equal sides count once)."""
    inner = [c for c in node.children if c.kind == "bsdf"]
    if len(inner) == 2 and material_key(inner[0]) == material_key(inner[1]):
        inner = inner[:1]
    if len(inner) != 1:
        raise SceneError(f"{what}: {node.label()} needs exactly one inner <bsdf>")
    return inner[0]


def material_key(node: XmlNode) -> tuple[str, str]:
    """Plugin and id, enough to tell a twosided's two sides apart when they are references."""
    return node.plugin, node.id


def material_of(node: XmlNode, what: str, base: Path, say: Say) -> Material | None:
    """The material of BSDF *node*; ``None`` where an approximation drops the shape (glass)."""
    name = node.id if node.id and not node.id.startswith("_unnamed") else ""
    while node.plugin == "twosided" or node.plugin in WRAPPERS:  # wrappers: mitsuba_maps
        node = inner_bsdf(node, what)
        name = name or (node.id if not node.id.startswith("_unnamed") else "")
    kind = node.plugin
    if kind not in _PARAMS:
        raise SceneError(
            f"{what}: unsupported element {node.label()}; expected a bsdf of type "
            + ", ".join([*_PARAMS, "twosided"])
        )
    extra = set(node.props) - _PARAMS[kind]
    if extra:
        raise SceneError(f"{what}: unsupported parameter {sorted(extra)[0]!r} in {node.label()}")
    if node.children:
        raise SceneError(
            f"{what}: unsupported element {node.children[0].label()} in {node.label()}"
        )
    rough = kind.startswith("rough")
    alpha = _number(node, "alpha", 0.1, what) if rough else 0.0
    if rough and node.props.get("distribution", "beckmann") != "ggx":
        shown = node.props.get("distribution", "beckmann (the default)")
        if say is None:
            raise SceneError(
                f"{what}: distribution {shown} in {node.label()}; only ggx has exact ground "
                "truth (--approximate would use ggx of the same alpha)"
            )
        say(f"{what}: {node.label()} distribution {shown} taken as ggx of the same alpha")
    if kind == "diffuse":
        spectrum = _colour(node, "reflectance", what, base, say)
        return Material(name or spectrum, spectrum)
    if kind in GLASS:
        return _glass(node, name, alpha, what, base, say)
    if kind.endswith("conductor"):
        metal = node.props.get("material", PERFECT_MIRROR)
        if not isinstance(metal, str) or not metal:
            raise SceneError(
                f"{what}: {node.label()} needs a 'material' (Au, Cu, Al, ..., none: a mirror)"
            )
        return Material(
            name or f"{kind} {metal}",
            METAL_SPECTRUM,
            kind="conductor",
            roughness=alpha,
            metal=metal,
            specular_reflectance=_tint(node, "specular_reflectance", what, base, say),
        )
    _unit_specular(node, what, say)
    spectrum = _colour(node, "diffuse_reflectance", what, base, say)
    ior = _number(node, "int_ior", 1.49, what) / _number(node, "ext_ior", 1.000277, what)
    return Material(
        name or f"{kind} {spectrum}", spectrum, kind="plastic", roughness=alpha, ior=ior
    )


def _ior(node: XmlNode, key: str, default: str, what: str) -> float:
    """``int_ior``/``ext_ior`` of *node*: a positive number, or a name in Mitsuba's table."""
    value = node.props.get(key, default)
    if isinstance(value, str):
        ior = named_ior(value)
        if ior is None:
            raise SceneError(
                f"{what}: {key} {value!r} in {node.label()}; expected a number or one of "
                "Mitsuba's named indices (bk7, water, air, acrylic glass, fused quartz, ...)"
            )
        return ior
    ior = _number(node, key, 0.0, what)
    if not ior > 0.0:
        raise SceneError(f"{what}: {key} {ior!r} in {node.label()}; expected a positive index")
    return ior


def _tint(node: XmlNode, key: str, what: str, base: Path, say: Say) -> str:
    """The tint *key* (``specular_transmittance``, ``specular_reflectance``) of glass *node* as
    a spectrum name, ``""`` where it is 1 (clear glass; a refused or approximated ``bitmap``
    too)."""
    value: Value | None = node.props.get(key)
    if isinstance(value, XmlNode) and value.plugin == "bitmap":
        if say is None:
            raise SceneError(
                f"{what}: {key} {value.label()} in {node.label()}: a textured tint has no exact "
                "ground truth; only a uniform rgb, spectrum or float (--approximate would use 1)"
            )
        say(f"{what}: {node.label()} textured {key} taken as 1")
        return ""
    unit = value is None or (isinstance(value, (int, float)) and value == 1.0)
    unit = unit or (isinstance(value, np.ndarray) and bool(np.all(value == 1.0)))
    return "" if unit else reflectance_name(value, f"{what} {key}", base)


def _glass(node: XmlNode, name: str, alpha: float, what: str, base: Path, say: Say) -> Material:
    """Glass of *node*, clear or tinted (module docstring); *alpha* already read for
    ``roughdielectric``."""
    inside, outside = _GLASS_IORS
    ior = _ior(node, "int_ior", inside, what) / _ior(node, "ext_ior", outside, what)
    kind: MaterialKind = "thindielectric" if node.plugin == "thindielectric" else "dielectric"
    return Material(
        name or f"{node.plugin} {ior:.4g}",
        METAL_SPECTRUM,
        kind=kind,
        roughness=alpha,
        ior=ior,
        transmittance=_tint(node, GLASS_TINTS["transmittance"], what, base, say),
        specular_reflectance=_tint(node, GLASS_TINTS["specular_reflectance"], what, base, say),
    )
