"""spectrinsic.decompose: intrinsic-image decomposers, error metrics and evaluation.

Decomposers (registry :data:`DECOMPOSERS`, plus plugins of the entry-point group
:data:`ENTRY_POINT_GROUP`): the thesis' names-and-shades method (chapter 3), colour Retinex
(Grosse et al. 2009) and two trivial baselines. Metrics (registry :data:`METRICS`) of thesis
section 2.4.3 and Eq. 4.31, the coloured-shading metrics (shading chromaticity, MAW-style
intensity/chromaticity split), plus WHDR on judgements derived from ground truth.
:func:`evaluate` reproduces the thesis' evaluations (Tables 5.1, 5.3, 5.4) on a rendered
dataset, for bundled methods and for :class:`Predictions` read from files.
"""

from .decomposition import Decomposer, Decomposition
from .evaluation.evaluate import EvaluationResult, Score, evaluate, evaluate_sample
from .evaluation.photometric import SCENARIOS, photometric_correction
from .evaluation.predictions import PredictionFiles, Predictions, write_predictions
from .methods.colour_naming import (
    COLOUR_NAMES,
    appendix_a_labels,
    colour_name_memberships,
    colour_names,
    discretise_memberships,
)
from .methods.registry import (
    DECOMPOSERS,
    ENTRY_POINT_GROUP,
    available_decomposers,
    decompose,
    get_decomposer,
)
from .metrics import METRICS, Metric, compute_metrics, get_metric, whdr
from .metrics.colour import (
    angular_error_mean,
    angular_error_median,
    reflectance_chromaticity_error,
    reflectance_intensity_error,
    shading_chromaticity_error,
)
from .metrics.judgements import Judgements, sample_judgements
from .metrics.scale import almse, correlation, dssim, lmse, local_correlation, mit_score, si_mse

__all__ = [
    "COLOUR_NAMES",
    "DECOMPOSERS",
    "ENTRY_POINT_GROUP",
    "METRICS",
    "SCENARIOS",
    "Decomposer",
    "Decomposition",
    "EvaluationResult",
    "Judgements",
    "Metric",
    "PredictionFiles",
    "Predictions",
    "Score",
    "almse",
    "angular_error_mean",
    "angular_error_median",
    "appendix_a_labels",
    "available_decomposers",
    "colour_name_memberships",
    "colour_names",
    "compute_metrics",
    "correlation",
    "decompose",
    "discretise_memberships",
    "dssim",
    "evaluate",
    "evaluate_sample",
    "get_decomposer",
    "get_metric",
    "lmse",
    "local_correlation",
    "mit_score",
    "photometric_correction",
    "reflectance_chromaticity_error",
    "reflectance_intensity_error",
    "sample_judgements",
    "shading_chromaticity_error",
    "si_mse",
    "whdr",
    "write_predictions",
]
