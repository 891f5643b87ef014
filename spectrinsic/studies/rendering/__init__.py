"""The rendered study (``spectrinsic study rendering``): colour error of diagonal renders with
all bounces, the rendered analogue of thesis Table 5.2, and the energy ratio r of Eq. 5.8.

Every complex library scene is rendered from each viewpoint under its two two-light conditions
(:data:`STUDY_CONDITIONS`, chosen from :data:`spectrinsic.scenes.CONDITIONS`).
The reference is the 31-band cube (``bands31``, 10 nm box bands integrated against the CIE 1931
CMFs; it agrees with Mitsuba's spectral variant within 0.5 % in mean colour, see
``tests/render``), rendered with the same paths as the approximations (common random numbers),
so the differences are spectral error, not Monte Carlo noise. Compared with it:

* ``rgb3``: 3-channel diagonal render with the CIE 1931 CMFs as sensors;
* ``gauss3``: 3 Gaussian sensors (thesis Table 5.2's set) regressed to XYZ;
* ``rgb6``: 6 Gaussian sensors (the thesis' two-pass method) regressed to XYZ on the Munsell
  chips under the scene's lights.

Per pixel the error is Eq. 5.7 on CIE XYZ, ``ε = ‖p − p̂‖₂ / ‖p‖₂``
(:func:`spectrinsic.spectra.relative_error`; XYZ: the space every mode is converted to; linear
sRGB would weigh channels differently but is a fixed linear map of it). Like the thesis, which
discards dark patches, pixels darker than :data:`DARK_FRACTION` of the image's 99th-percentile
luminance are left out, as are pixels not covered mostly by a material (visible light sources).
The energy ratio ``r = Σ‖p¹‖ / Σ‖p^∞‖`` uses the reference's direct-only render (path depth 2)
and full render (depth :data:`MAX_DEPTH`).

- :mod:`.compute`: presets, one sample's render and numbers, the summary;
- :mod:`.report`: :func:`run_rendering_study` (writes the files) and the text table;
- :mod:`.plot`: the per-sample error figure.
"""

from .compute import (
    COMPARED_MODES,
    DARK_FRACTION,
    MAX_DEPTH,
    QUALITIES,
    REFERENCE_MODE,
    STUDY_CONDITIONS,
    THESIS_MEAN_R,
    SampleResult,
    StudyQuality,
    error_stats,
    evaluate_sample,
    valid_pixels,
)
from .plot import error_figure
from .report import (
    RenderingResult,
    RenderingSettings,
    format_rendering,
    rendering_payload,
    run_rendering,
    run_rendering_study,
    write_rendering_outputs,
)

__all__ = [
    "QUALITIES",
    "StudyQuality",
    "REFERENCE_MODE",
    "COMPARED_MODES",
    "STUDY_CONDITIONS",
    "DARK_FRACTION",
    "MAX_DEPTH",
    "THESIS_MEAN_R",
    "SampleResult",
    "valid_pixels",
    "error_stats",
    "evaluate_sample",
    "RenderingSettings",
    "RenderingResult",
    "run_rendering",
    "rendering_payload",
    "write_rendering_outputs",
    "run_rendering_study",
    "format_rendering",
    "error_figure",
]
