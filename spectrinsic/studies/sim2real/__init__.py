"""The sim-to-real study (``spectrinsic study sim2real``): the reference U-Net trained on
matched generated sets differing in one factor (spectral image, coloured lights, camera
chain), scored on the MIT photographs and a held-out synthetic split; docs/sim2real.md."""

from __future__ import annotations

from .compute import BASELINES, RunScore, Sim2RealResult, dataset_config, run_sim2real
from .report import arm_rows, factor_rows, format_sim2real, write_sim2real
from .settings import FACTORS, PRESETS, Arm, Sim2RealSettings, arms, preset
from .stats import Interval, paired_difference, t_interval

__all__ = [
    "BASELINES",
    "RunScore",
    "Sim2RealResult",
    "dataset_config",
    "run_sim2real",
    "arm_rows",
    "factor_rows",
    "format_sim2real",
    "write_sim2real",
    "FACTORS",
    "PRESETS",
    "Arm",
    "Sim2RealSettings",
    "arms",
    "preset",
    "Interval",
    "paired_difference",
    "t_interval",
]
