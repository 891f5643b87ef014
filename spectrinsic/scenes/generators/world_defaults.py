"""What a generated set holds unless told otherwise: a share of glossy, metallic and textured
surfaces, so a generated set looks like the world rather than a matte, untextured one.

The library layout stays the thesis' (matte; its ``*-glossy`` variants are separate scenes).
The shares are the defaults of ``spectrinsic dataset --glossy / --metallic /
--texture-fraction``; a build records them in its config's ``source`` (and so in its config
hash), and ``--glossy 0 --metallic 0 --texture-fraction 0`` builds the matte world of earlier
versions with its old config hash.

Why these numbers: indoor scenes are mostly matte (walls, fabric, wood), with a visible minority
of coated surfaces (painted or varnished furniture, plastics, ceramics) and a few metals
(fittings, cutlery, frames). The shares are a judgement of that order of magnitude, not a
measurement of any material statistics.
"""

from __future__ import annotations

__all__ = ["GLOSSY_FRACTION", "METALLIC_FRACTION", "TEXTURE_FRACTION"]

#: Share of generated materials made coated/glossy (Mitsuba ``plastic``/``roughplastic``).
GLOSSY_FRACTION = 0.25
#: Share of generated materials made metal (Ag, Al, Au, Cu, Cr; Mitsuba's measured η/k).
METALLIC_FRACTION = 0.10
#: Share of generated objects given a per-pixel spectral texture (wood rings, weave, noise).
TEXTURE_FRACTION = 0.20
