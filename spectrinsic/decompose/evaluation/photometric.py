"""Photometric pre-correction of camera images before decomposition (thesis ch. 4, sec. 5.1.3).

The general model (Eq. 4.22, Lambertian case 4.23) writes a camera pixel as
``p = L_CLig . S_Sen . p^{s,c}``: ``S_Sen`` maps the canonical representation (sRGB sensors
under D65) to the camera's sensors, ``L_CLig`` maps the canonical light to the scene's light in
the camera's space (Eq. 4.16). Removing them before a decomposition lets it estimate *absolute*
reflectance. Section 5.1.3 evaluates three scenarios:

* **SC1** camera and light known, full model: ``p^{s,c} = S_Sen^-1 L_CLig^-1 p``;
* **SC3b** camera unknown (standard sensors assumed), light known, full model:
  ``p^{s,c} = L_CLig^-1 p`` with the illuminant matrix fitted for sRGB sensors;
* **SC4** nothing known: the image is used as it is.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import numpy.typing as npt

from ...errors import DecomposeError, validate_choice
from .._validation import ImageShapeError, as_image

__all__ = ["SCENARIOS", "Scenario", "photometric_correction", "correction_matrix"]

Scenario = Literal["SC1", "SC3b", "SC4"]
#: The photometric scenarios of the evaluation (thesis sec. 5.1.3) and what each needs: the one
#: registry of scenario names a camera image is corrected for (``evaluate``, ``report`` and the
#: predictions layout's ``<scenario>`` folders use these keys, in this order). Study tables with
#: other columns (Table 5.1's SC1-SC4) are not this registry.
SCENARIOS: dict[str, str] = {
    "SC1": "camera sensors and light known: remove S_Sen and L_CLig (full 3x3 models)",
    "SC3b": "light known, standard sensors assumed: remove L_CLig fitted for sRGB sensors",
    "SC4": "nothing known: white light and sRGB sensors assumed, no correction",
}


def _matrix(value: npt.ArrayLike | None, what: str, scenario: str) -> np.ndarray:
    if value is None:
        raise ImageShapeError(f"scenario {scenario} needs the {what} matrix; got None")
    m = np.asarray(value, dtype=np.float64)
    if m.shape != (3, 3) or not np.all(np.isfinite(m)):
        raise ImageShapeError(f"{what} must be a finite 3x3 matrix; got shape {m.shape}")
    if abs(np.linalg.det(m)) < 1e-12:
        raise ImageShapeError(f"{what} is singular and cannot be inverted")
    return m


def correction_matrix(
    scenario: str,
    *,
    L_CLig: npt.ArrayLike | None = None,  # noqa: N803 - the thesis' symbol
    S_Sen: npt.ArrayLike | None = None,  # noqa: N803
) -> np.ndarray:
    """The ``(3, 3)`` matrix ``C`` with ``p^{s,c} = C p`` for *scenario* (Eqs. 4.16, 4.23).

    Parameters
    ----------
    scenario
        ``"SC1"``, ``"SC3b"`` or ``"SC4"``.
    L_CLig
        Illuminant transformation acting on column vectors (camera space for SC1, sRGB-sensor
        space for SC3b).
    S_Sen
        Sensor transformation (SC1 only).
    """
    validate_choice(scenario, SCENARIOS, "photometric scenario", error=DecomposeError)
    if scenario == "SC4":
        return np.eye(3)
    light = _matrix(L_CLig, "L_CLig", scenario)
    if scenario == "SC3b":
        return np.linalg.inv(light)
    sensor = _matrix(S_Sen, "S_Sen", scenario)
    return np.linalg.inv(light @ sensor)


def photometric_correction(
    image: npt.ArrayLike,
    scenario: str,
    *,
    L_CLig: npt.ArrayLike | None = None,  # noqa: N803
    S_Sen: npt.ArrayLike | None = None,  # noqa: N803
) -> np.ndarray:
    """Apply the inverse light and sensor matrices of *scenario* to a linear ``(H, W, 3)`` image.

    Returns the corrected float64 image ``C p`` per pixel (:func:`correction_matrix`), negative
    values clipped to 0 (a full 3x3 inverse can undershoot on saturated colours).
    """
    img = as_image(image, "image", channels=3)
    c = correction_matrix(scenario, L_CLig=L_CLig, S_Sen=S_Sen)
    return np.clip(img @ c.T, 0.0, None)
