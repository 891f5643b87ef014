"""Means with Student-t 95 % confidence intervals, and paired differences between arms."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["CONFIDENCE", "Interval", "t_interval", "paired_difference"]

#: Two-sided confidence of every interval.
CONFIDENCE = 0.95


@dataclass(frozen=True)
class Interval:
    """``mean`` and its ``lo``..``hi`` t-interval over ``n`` values (NaN bounds for n < 2)."""

    mean: float
    lo: float
    hi: float
    n: int

    @property
    def significant(self) -> bool:
        """The interval excludes 0 (for a difference: the arms differ at this confidence)."""
        return bool(self.lo > 0.0 or self.hi < 0.0)


def t_interval(values: Sequence[float], confidence: float = CONFIDENCE) -> Interval:
    """Mean ± t_{(1+c)/2, n-1} · s / √n (s the sample standard deviation, ddof = 1).

    >>> iv = t_interval([1.0, 2.0, 3.0])  # t_{0.975, 2} = 4.303, s / √3 = 0.577
    >>> round(iv.mean, 3), round(iv.hi - iv.mean, 3)
    (2.0, 2.484)
    """
    from scipy import stats

    x = np.asarray(values, np.float64)
    n = int(x.size)
    mean = float(x.mean()) if n else math.nan
    if n < 2:
        return Interval(mean, math.nan, math.nan, n)
    half = float(stats.t.ppf(0.5 + confidence / 2, n - 1) * x.std(ddof=1) / math.sqrt(n))
    return Interval(mean, mean - half, mean + half, n)


def paired_difference(a: Sequence[float], b: Sequence[float]) -> Interval:
    """The t-interval of ``a_i - b_i`` over runs paired by seed (same seed, one factor apart)."""
    if len(a) != len(b):
        raise ValueError(f"paired difference of {len(a)} and {len(b)} values")
    return t_interval([x - y for x, y in zip(a, b, strict=True)])
