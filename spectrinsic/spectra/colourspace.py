"""The sRGB colour space's matrices (IEC 61966-2-1, D65 white), computed on first use.

A base module of :mod:`spectrinsic.spectra`: it imports no other spectra module, so both the
colour maths (:mod:`~spectrinsic.spectra.colorimetry`) and the sensor sets
(:mod:`~spectrinsic.spectra.sensors`, whose ``"srgb"`` curves are the matrix times the CIE 1931
colour-matching functions) can use it without importing each other.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["srgb_matrices"]


@functools.cache
def srgb_matrices() -> tuple[np.ndarray, np.ndarray]:
    """``(M_XYZ→sRGB, M_sRGB→XYZ)``: the ``(3, 3)`` float64 matrices taking CIE 1931 XYZ to
    linear sRGB and back, from colour-science, read-only (computed once, on first call).

    >>> to_rgb, to_xyz = srgb_matrices()
    >>> to_xyz[1].tolist(), to_rgb.flags.writeable  # Y = 0.2126 R + 0.7152 G + 0.0722 B
    ([0.2126, 0.7152, 0.0722], False)
    """
    import colour

    cs = colour.RGB_COLOURSPACES["sRGB"]
    to_rgb = np.array(cs.matrix_XYZ_to_RGB, dtype=np.float64)
    to_xyz = np.array(cs.matrix_RGB_to_XYZ, dtype=np.float64)
    for matrix in (to_rgb, to_xyz):
        matrix.flags.writeable = False
    return to_rgb, to_xyz
