"""Scoring on a camera's processed image (samples built with ``dataset --camera NAME``).

Such a sample holds the camera chain's processed linear image, noise included
(``image_sensor_noisy/<camera>``: demosaicked, white-balanced, colour-matrixed linear sRGB), and
its ground truth carried through the same linear stages (``reflectance_sensor/<camera>``,
``shading_sensor/<camera>``; :mod:`spectrinsic.gt_export.sample.sensor`). The evaluation's scenario
``sensor_<camera slug>`` gives a method that image and scores its estimates against that carried
ground truth, with the metrics of the ``srgb`` scenario (reflectance, shading in grey and colour).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ...gt_export.formats.names import camera_slug

__all__ = ["PROCESSED_INPUT", "processed_inputs"]

#: Loader-key prefix of the processed linear image a method is given.
PROCESSED_INPUT = "image_sensor_noisy/"


def processed_inputs(
    sample: Mapping[str, Any], target: str = "full"
) -> list[tuple[str, np.ndarray, dict[str, np.ndarray]]]:
    """``(scenario, image, ground-truth layers)`` per camera chain of *sample*: the processed
    linear image (less ``specular_sensor/<camera>`` for the ``"diffuse"`` target) and the
    carried ``reflectance``, ``shading`` and their grey versions (``(H, W)`` channel means)."""
    out = []
    for key in sorted(k for k in sample if isinstance(k, str) and k.startswith(PROCESSED_INPUT)):
        camera = key.removeprefix(PROCESSED_INPUT)
        refl_key, shading_key = f"reflectance_sensor/{camera}", f"shading_sensor/{camera}"
        if refl_key not in sample or shading_key not in sample:
            continue
        image = np.asarray(sample[key], dtype=np.float64)
        specular = sample.get(f"specular_sensor/{camera}")
        if target == "diffuse" and specular is not None:
            image = image - np.asarray(specular, dtype=np.float64)
        refl = np.asarray(sample[refl_key], dtype=np.float64)
        shading = np.asarray(sample[shading_key], dtype=np.float64)
        layers = {
            "reflectance": refl,
            "shading": shading,
            "shading_grey": shading.mean(axis=2),
            "reflectance_grey": refl.mean(axis=2),
        }
        out.append((f"sensor_{camera_slug(camera)}", image, layers))
    return out
