"""spectrinsic: spectral rendering of synthetic intrinsic-image datasets.

Layers, each importing only those before it: the base modules (:mod:`spectrinsic.errors`,
``arrays``, ``data_dir``, ``rng``, ``provenance``, ``results``, ``interrupts``, ``threads``); the
data-flow packages :mod:`spectrinsic.spectra` (measured spectra and colour maths),
:mod:`spectrinsic.scenes` (scenes as plain data), :mod:`spectrinsic.render` (Mitsuba 3
backends), :mod:`spectrinsic.gt_export` (ground-truth layers, writers, loader) and
:mod:`spectrinsic.decompose` (decomposers, metrics, evaluation); then the top:
:mod:`spectrinsic.pipeline` (the dataset build), :mod:`spectrinsic.studies`,
:mod:`spectrinsic.bench` and :mod:`spectrinsic.cli`.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from .errors import SpectrinsicError, SpectrinsicWarning

try:
    __version__ = version("spectrinsic")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

__all__ = ["__version__", "SpectrinsicError", "SpectrinsicWarning"]
