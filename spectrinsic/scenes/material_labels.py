"""How a sample names its materials in ``meta.json``'s ``materials``: the reflectance spectrum
of a diffuse or coated material, ``metal:<symbol>`` for a metal.

A metal has no diffuse lobe (its diffuse spectrum is ``flat:0``,
:data:`spectrinsic.scenes.materials.METAL_SPECTRUM`), so its spectrum name says nothing about
it; the label names the η/k table Mitsuba renders it with (``metal:Au``, ``metal:Cu``).
:func:`label_spectrum` turns a label back into the diffuse reflectance spectrum name, for
readers that integrate it (chroma figures, provenance).

>>> from spectrinsic.scenes.model import Material
>>> material_label(Material("gold", "flat:0", kind="conductor", metal="Au"))
'metal:Au'
>>> material_label(Material("red", "munsell:5R 4/14"))
'munsell:5R 4/14'
>>> label_spectrum("metal:Au"), label_spectrum("munsell:5R 4/14")
('flat:0', 'munsell:5R 4/14')
"""

from __future__ import annotations

from .materials import METAL_SPECTRUM
from .model import Material

__all__ = ["METAL_PREFIX", "label_spectrum", "material_label"]

#: Prefix of a metal's label.
METAL_PREFIX = "metal:"


def material_label(material: Material) -> str:
    """``metal:<symbol>`` for a conductor, else the material's reflectance spectrum name."""
    if material.kind == "conductor" and material.metal:
        return f"{METAL_PREFIX}{material.metal}"
    return material.spectrum


def label_spectrum(label: str) -> str:
    """The diffuse reflectance spectrum name of a material *label* (``flat:0`` for a metal)."""
    return METAL_SPECTRUM if label.startswith(METAL_PREFIX) else label
