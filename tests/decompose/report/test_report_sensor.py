"""Issue 47: REPORT.md shows the camera-chain scenario (``sensor_<camera>``) that ``evaluate``
scores on a ``dataset --camera`` set, as the mean over samples of each metric."""

from __future__ import annotations

import math

from spectrinsic.decompose.evaluation.scores import Score
from spectrinsic.decompose.report.sensor import sensor_md, sensor_table


def _score(sample, scenario, layer, metric, value):
    return Score(sample, "m", scenario, layer, metric, value)


def test_the_sensor_table_averages_each_metric_over_the_samples():
    scores = [
        _score("a", "sensor_nikon-5100-npl", "reflectance", "si_mse", 0.1),
        _score("b", "sensor_nikon-5100-npl", "reflectance", "si_mse", 0.3),
        _score("a", "sensor_nikon-5100-npl", "shading_grey", "lmse", float("nan")),
        _score("a", "srgb", "reflectance", "si_mse", 9.0),  # not a camera chain's
    ]
    (row,) = sensor_table(scores)
    assert row["camera"] == "nikon-5100-npl" and row["method"] == "m"
    assert math.isclose(row["refl_mse"], 0.2) and math.isnan(row["grey_lmse"])
    text = "\n".join(sensor_md([row]))
    assert "## Camera chain" in text and "| nikon-5100-npl | m | — | 0.2 |" in text
    assert sensor_md(sensor_table(scores[3:])) == []
