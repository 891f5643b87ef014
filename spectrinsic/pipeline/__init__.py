"""The dataset build: presets, sample planning, per-sample work, executors and scene sources.

Orchestration only: it calls :mod:`spectrinsic.scenes`, :mod:`spectrinsic.render` and
:mod:`spectrinsic.gt_export` and holds no physics of its own. Imported by the CLI and the
benchmarks, never by the data-flow packages.
"""
