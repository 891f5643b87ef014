"""The dataset card's words that depend on the set: the colour conventions of its own working
space (its white, the sign of its shading, where out-of-gamut light goes) and percentages
written for people.

A set in ``srgb`` clips the shading's negative components into the residual; a set in
``acescg`` or ``rec2020`` keeps them in the shading (``spectrinsic/spectra/working_space.py``),
so its card must not describe a clip that never happened.
"""

from __future__ import annotations

from collections.abc import Sequence

from ...spectra.working_space import WorkingSpace

__all__ = ["percent", "colour_conventions"]


def percent(fraction: float) -> str:
    """A fraction as a percentage a person reads: 3 significant figures at most, never in
    exponent notation.

    >>> [percent(f) for f in (0.999, 0.0237, 0.000123, 0.0, 1.0)]
    ['99.9 %', '2.37 %', '0.0123 %', '0 %', '100 %']
    """
    value = 100.0 * float(fraction)
    if value == 0:
        return "0 %"
    digits = max(0, 2 - int(f"{abs(value):e}".split("e")[1]))
    text = f"{value:.{digits}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return f"{text} %"


def _triple(values: Sequence[float]) -> str:
    return "(" + ", ".join(f"{v:.3f}" for v in values) + ")"


def _space_bullet(space: WorkingSpace) -> str:
    white = _triple(space.white.tolist())
    kept = (
        "with the shading's negative components set to 0 and moved into the residual"
        if space.clip_shading
        else "with the shading's negative components kept (light outside the space's gamut "
        "stays in the shading, none goes into the residual)"
    )
    return (
        f"* **Working space: {space.colourspace}** (`{space.name}`). The RGB layers (`image*`, "
        "`reflectance`, `shading*`, `illuminant`, `specular`, `residual*`) are linear "
        f'{space.colourspace}, `meta.json["working_space"]` (name, `xyz_to_rgb`, '
        "`rgb_to_xyz`, `rgb_to_srgb` matrices and `white_d65`, the space's colour of the "
        f"perfect white under D65), {kept}. In {space.colourspace} the perfect white's "
        f"reflectance is `white_d65` = {white}, and D65 light's shading is (1, 1, 1). PNG "
        "previews always show the **sRGB view** (`rgb_to_srgb`, the light relative to sRGB's "
        'white, limited to [0, 1] for display); `load_sample(path, space="srgb")` returns that '
        "view, with the residuals recomputed so every identity holds in it; `spectrinsic "
        "evaluate` scores in it. The default working space is ACEScg: over 200 generated rooms "
        "it halves linear sRGB's residual share, and no pixel's shading leaves its gamut."
    )


def _shading_sign(space: WorkingSpace) -> str:
    if space.clip_shading:
        return (
            "finite and ≥ 0 (negative, out-of-gamut components are clipped into the residual; "
            '`meta.json["shading_clipping"]` gives the fraction of lit pixels affected and the '
            "clipped part's size relative to the shading). Out-of-gamut light comes from bounces "
            "off saturated surfaces and from lights at the gamut's edge: high-pressure sodium "
            "(HP1) has an sRGB blue of 6e-6 at unit luminance, which the 10 nm bands of the cube "
            "turn slightly negative, so nearly every pixel it lights loses that tiny amount."
        )
    return (
        f"finite; a channel is negative where the light lies outside {space.colourspace}'s "
        "gamut, and stays so: nothing moves into the residual "
        '(`meta.json["shading_clipping"]["pixels"]` gives the share of lit pixels with a '
        "negative channel, the card's out-of-gamut share below)."
    )


def colour_conventions(spaces: Sequence[WorkingSpace]) -> dict[str, str]:
    """The card template's fields that depend on the set's working space(s): ``space_bullet``,
    ``white`` (the perfect white's reflectance), ``shading_sign`` and ``residual_gamut``."""
    by_name = {s.name: s for s in spaces}
    if len(by_name) != 1:
        names = ", ".join(s.colourspace for _, s in sorted(by_name.items()))
        return {
            "space_bullet": "\n".join(_space_bullet(s) for _, s in sorted(by_name.items())),
            "white": f"the space's `white_d65` (the samples mix working spaces: {names})",
            "shading_sign": "finite; its sign depends on each sample's working space (above).",
            "residual_gamut": ", and in sets that clip their shading the out-of-gamut light",
        }
    space = spaces[0]
    return {
        "space_bullet": _space_bullet(space),
        "white": f"`white_d65` = {_triple(space.white.tolist())} in {space.colourspace}",
        "shading_sign": _shading_sign(space),
        "residual_gamut": " plus the clipped out-of-gamut light" if space.clip_shading else "",
    }
