"""The vocabulary of an evaluation, shared by the scorer and the report writer: one
:class:`Score` per number of ``scores.csv``, the lighting-condition groups of Tables 5.3/5.4,
the input layers a method decomposes and the layers scored.

It sits below both :mod:`spectrinsic.decompose.evaluation.evaluate` (which makes scores) and
:mod:`spectrinsic.decompose.report` (which writes them), so neither imports the other's
module for a name.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CONDITION_GROUPS", "condition_group", "INPUT_LAYERS", "SCORED_LAYERS", "Score"]

#: Lighting conditions of the dataset and the column of Tables 5.3/5.4 each belongs to.
CONDITION_GROUPS: dict[str, str] = {
    "white": "WL",
    "one-colour": "1L",
    "two-colour-a": "2L",
    "two-colour-b": "2L",
}


def condition_group(condition: str) -> str:
    """The lighting group (WL/1L/2L) of *condition*: a library condition's
    (:data:`CONDITION_GROUPS`), else *condition* itself, a group measured from a sample's
    lights (:func:`spectrinsic.decompose.evaluation.sample_fields.sample_condition`)."""
    return CONDITION_GROUPS.get(condition, condition)


#: The image a method decomposes: the first of these layers a sample has. ``image_denoised``
#: (``reflectance * shading + residual`` exactly, from the denoised irradiance) is the input
#: consistent with the ground truth; ``image`` is the raw Monte Carlo rendering.
INPUT_LAYERS: tuple[str, ...] = ("image_denoised", "image")
#: Layers scored, and what each one is: the thesis scores shading in grey (sec. 5.2.5), the
#: coloured-shading literature scores its colour too.
SCORED_LAYERS: dict[str, str] = {
    "reflectance": "`reflectance` (absolute, linear sRGB under D65) against the estimate, in colour",
    "shading_grey": "`shading_grey` (luminance Y of the irradiance) against the estimate's mean "
    "over channels (thesis sec. 5.2.5: grey shading)",
    "shading": "`shading` (linear-sRGB colour of the irradiance, material-free) against the "
    "estimate's coloured shading (`image / reflectance`)",
    "reflectance_grey": "mean over channels of `reflectance` against that of the estimate "
    '(thesis Tables 3.1/3.2: "grayscale reflectances")',
}


@dataclass(frozen=True)
class Score:
    """One number of ``scores.csv``; ``camera`` and ``photometric`` only for camera scenarios."""

    sample: str
    method: str
    scenario: str
    layer: str
    metric: str
    value: float
    camera: str = ""
    photometric: str = ""
