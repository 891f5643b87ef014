"""What an evaluation scores against: the full image or its diffuse part, and the predicted
``specular`` layer (issue 21, thesis ch. 4: ``I = L_CLig · S_Sen · (I_Shad ∘ I_Refl + I_Spec)``).

A glossy sample (:mod:`spectrinsic.gt_export.layers.gloss`) satisfies::

    image = reflectance ∘ shading + specular + residual

so a decomposition ``image = reflectance ∘ shading`` (thesis Eq. 3.1) cannot be exact on the
full image where ``specular`` ≠ 0. The *target* says which image a method is given:

* ``"full"`` (default): the input layer as it is (:data:`~spectrinsic.decompose.evaluation.scores.
  INPUT_LAYERS`); highlights are part of what a method must explain;
* ``"diffuse"``: the input layer less the sample's ``specular`` layer (``specular_camera/<name>``
  for a camera image), i.e. ``reflectance ∘ shading + residual``; for a matte sample (no
  ``specular`` layer: its specular part is 0) both targets are the same image.

The ground truth scored (``reflectance``, ``shading``) is the same for both targets. A method
may also predict ``specular`` (linear sRGB, render units, any scale); it is scored against the
sample's ``specular`` layer with :data:`SPECULAR_METRICS` on the sRGB input.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ...errors import DatasetError, validate_choice
from ...gt_export.layers.gloss import SPECULAR

__all__ = [
    "TARGETS",
    "SPECULAR_LAYER",
    "SPECULAR_METRICS",
    "specular_key",
    "target_image",
    "target_note",
]

#: Images an evaluation may decompose (module docstring).
TARGETS = ("full", "diffuse")
#: The ground-truth layer a predicted specular image is scored against.
SPECULAR_LAYER = SPECULAR
#: Metrics of a predicted ``specular`` layer: scale-invariant MSE (Eq. 2.4) and LMSE, both fit
#: a scale as for the other layers.
SPECULAR_METRICS = ("si_mse", "lmse")

_TEXT = {
    "full": "the full image (`image = reflectance ∘ shading + specular + residual`; highlights "
    "included)",
    "diffuse": "the diffuse image: the input layer less the sample's `specular` layer "
    "(`reflectance ∘ shading + residual`)",
}


def specular_key(camera: str | None = None) -> str:
    """Loader key of the specular layer: ``specular`` or ``specular_camera/<camera>``."""
    return f"specular_camera/{camera}" if camera else SPECULAR_LAYER


def target_image(
    sample: Mapping[str, Any], image: np.ndarray, target: str, camera: str | None = None
) -> np.ndarray:
    """*image* (float64 ``(H, W, 3)``, the sample's input layer) as the *target* asks.

    ``"diffuse"`` subtracts the sample's specular layer (of *camera* when given); a sample
    without one is matte and its image is returned unchanged.
    """
    validate_choice(target, TARGETS, "evaluation target", error=DatasetError)
    spec = sample.get(specular_key(camera))
    if target == "full" or spec is None:
        return image
    return np.asarray(image, dtype=np.float64) - np.asarray(spec, dtype=np.float64)


def target_note(target: str, glossy: bool) -> str:
    """The line the report and tables print about the target; empty for the default target on
    matte samples (where both targets are the same image), so those outputs stay as before."""
    validate_choice(target, TARGETS, "evaluation target", error=DatasetError)
    if target == "full" and not glossy:
        return ""
    spec = (
        f" A predicted `specular` is scored against the sample's `specular` layer "
        f"({', '.join(SPECULAR_METRICS)})."
        if glossy
        else ""
    )
    return f"Target: {target} — methods decompose {_TEXT[target]}.{spec}"
