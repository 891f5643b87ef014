"""The thesis' studies: Table 5.2 (``reconstruction``), Table 4.4 (``photometric``) and the
rendered accuracy study (``rendering``). Each computes, reports and plots; the physics they use
lives in :mod:`spectrinsic.spectra` and :mod:`spectrinsic.render`. :mod:`.registry` holds them
behind one protocol (settings, run, format, write) and runs any of them
(:func:`~spectrinsic.studies.registry.run_study`).
"""
