"""Gloss of ``.blend`` materials: :func:`principled_gloss` (metal, coat, glass; the rules are in
:mod:`~spectrinsic.scenes.blender`'s docstring) and glass, a Principled BSDF of Transmission 1
or a Glass BSDF node (:func:`material_glass`).

A Principled BSDF whose ``Transmission Weight`` (Blender 4; ``Transmission`` in 3.x) is 1 and
``Metallic`` below 0.5, or a material whose only shader is a Glass BSDF (``BSDF_GLASS``), is
glass: :class:`~spectrinsic.scenes.model.Material` kind ``dielectric`` of the node's IOR (within
the scene format's range) and GGX α = Roughness² (Blender's convention). Blender's glass is a
solid (a thin pane is modelled with two faces, as in Blender).

Tints, as Cycles applies them (Blender 4): the Principled BSDF tints each transmission (not its
reflection) by √(Base Color), so that light entering and leaving a solid is tinted by Base
Color; its ``transmittance`` is ``rgb:`` of those square roots (linear Rec. 709 from the file's
working space, Mallett–Yuksel upsampled, as every Blender colour). Blender 3.x's Principled
BSDF (input ``Transmission``) tinted otherwise: a tint there is refused. The Glass BSDF's Color
tints reflection and transmission alike, once per interaction (no square root): its
``transmittance`` and ``specular_reflectance`` are both ``rgb:`` of the Color (Cycles'
``intern/cycles/kernel/svm/closure.h``, ``CLOSURE_BSDF_MICROFACET_GGX_GLASS_ID``: the
Fresnel's ``reflection_tint`` and ``transmission_tint`` are both the node's colour; Blender 3.x
weights its reflection and refraction closures by the colour too).

Refused in one line naming the material, since they have no exact ground truth: a transmission
strictly between 0 and 1 (a mix of glass and the diffuse base), a textured tint (a Base Color
or Glass Color fed by a node), and a rough Glass BSDF whose
distribution is not GGX. Pure Python over duck-typed ``bpy`` objects, so it needs no ``bpy``
to test.
"""

from __future__ import annotations

from typing import Any

from ..errors import SceneError
from .blender_colours import principled_node
from .blender_working_space import rec709_colour
from .materials import IOR_RANGE

__all__ = ["METAL_PROPERTY", "DEFAULT_METAL", "principled_gloss", "material_glass"]

#: Custom property of a metallic material naming its conductor (Mitsuba η/k table), and the default.
METAL_PROPERTY = "metal"
DEFAULT_METAL = "Al"

#: The Principled BSDF's transmission input, Blender 4 and 3.x names.
_TRANSMISSION = ("Transmission Weight", "Transmission")


def _nodes(mat: Any) -> list[Any]:
    tree = getattr(mat, "node_tree", None)
    return [] if tree is None else list(tree.nodes)


def _colour(mat: Any, node: Any, colour: str) -> list[float]:
    """The unlinked RGB of *node*'s input *colour* in linear Rec. 709 (from the file's working
    space), in [0, 1]; a linked one (a textured tint) or one out of range is refused."""
    socket = node.inputs[colour]
    if socket.is_linked:
        raise SceneError(
            f"material {mat.name!r}: glass with its {colour} fed by a node; a textured tint "
            "has no exact ground truth (set a uniform colour)"
        )
    rgb = list(rec709_colour(socket.default_value, f"material {mat.name!r}: glass {colour}"))
    if not all(0.0 <= c <= 1.0 for c in rgb):
        raise SceneError(
            f"material {mat.name!r}: glass {colour} {rgb} (linear Rec. 709); expected values "
            "in [0, 1]"
        )
    return rgb


def _principled_tint(mat: Any, node: Any, key: str) -> dict[str, str]:
    """``{"transmittance": "rgb:..."}`` of √(Base Color) (module docstring), ``{}`` if white;
    a tint under Blender 3.x's input *key* ``Transmission`` is refused."""
    rgb = _colour(mat, node, "Base Color")
    if rgb == [1.0, 1.0, 1.0]:
        return {}
    if key != _TRANSMISSION[0]:
        raise SceneError(
            f"material {mat.name!r}: glass with Base Color {rgb} under Blender 3.x's "
            f"{key!r}; tints are read as Blender 4's Principled BSDF applies them only"
        )
    return {"transmittance": "rgb:" + ",".join(f"{c**0.5:.9g}" for c in rgb)}


def _glass_tint(mat: Any, node: Any) -> dict[str, str]:
    """``transmittance`` and ``specular_reflectance`` both ``rgb:`` of a Glass BSDF's Color
    (module docstring), ``{}`` if white."""
    rgb = _colour(mat, node, "Color")
    if rgb == [1.0, 1.0, 1.0]:
        return {}
    name = "rgb:" + ",".join(f"{c:.9g}" for c in rgb)
    return {"transmittance": name, "specular_reflectance": name}


def _fields(node: Any) -> dict[str, Any]:
    rough = min(max(float(node.inputs["Roughness"].default_value), 0.0), 1.0)
    ior = float(node.inputs["IOR"].default_value) if "IOR" in node.inputs else 1.5
    ior = min(max(ior, IOR_RANGE[0] + 1e-3), IOR_RANGE[1])
    return {"kind": "dielectric", "ior": ior, "roughness": rough**2}


def material_glass(mat: Any) -> dict[str, Any] | None:
    """Gloss fields of glass material *mat* (module docstring), or ``None`` if not glass."""
    nodes = _nodes(mat)
    principled = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
    if principled is not None:
        key = next((k for k in _TRANSMISSION if k in principled.inputs), None)
        weight = 0.0 if key is None else float(principled.inputs[key].default_value)
        if (
            key is None
            or weight == 0.0
            or float(principled.inputs["Metallic"].default_value) >= 0.5
        ):
            return None
        if weight != 1.0:
            raise SceneError(
                f"material {mat.name!r}: Principled {key} {weight:g}; only 1 (glass) or 0 "
                "has exact ground truth"
            )
        return _fields(principled) | _principled_tint(mat, principled, key)
    glass = next((n for n in nodes if n.type == "BSDF_GLASS"), None)
    if glass is None:
        return None
    fields = _fields(glass) | _glass_tint(mat, glass)
    distribution = str(getattr(glass, "distribution", "GGX"))
    if fields["roughness"] > 0.0 and distribution != "GGX":
        raise SceneError(
            f"material {mat.name!r}: Glass BSDF distribution {distribution}; only GGX has exact "
            "ground truth when rough"
        )
    return fields


def principled_gloss(mat: Any) -> dict[str, Any]:
    """Gloss fields of :class:`Material` from *mat*'s first Principled BSDF node (module
    docstring); ``{}`` (Lambertian) without one or when it is matte."""
    glass, node = material_glass(mat), principled_node(mat)
    if glass is not None or node is None:
        return glass or {}
    rough = float(node.inputs["Roughness"].default_value)
    alpha = min(max(rough, 0.0), 1.0) ** 2
    if float(node.inputs["Metallic"].default_value) >= 0.5:
        metal = str(mat[METAL_PROPERTY]) if METAL_PROPERTY in mat.keys() else DEFAULT_METAL
        return {"kind": "conductor", "metal": metal, "roughness": alpha}
    if rough < 0.5:
        ior = float(node.inputs["IOR"].default_value) if "IOR" in node.inputs else 1.5
        return {
            "kind": "plastic",
            "roughness": alpha,
            "ior": min(max(ior, IOR_RANGE[0] + 1e-3), IOR_RANGE[1]),
        }
    return {}
