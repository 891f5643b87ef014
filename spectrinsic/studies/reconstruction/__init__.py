"""Reconstruction error of the diagonal (K-channel) rendering model: thesis Table 5.2 and beyond.

Renderers approximate a sensor response ``p_k = ∫ f L S_k dλ`` (Eq. 4.9) by the product of
separately integrated material and light values, ``p̂_k = (∫ f S_k dλ)(∫ L S_k dλ)`` (Eq. 5.2),
and after two bounces ``p̂ = f₂ ∘ f₁ ∘ L`` (second term of Eq. 5.6). Section 5.2.3 measures the
relative error ``ε = ‖p − p̂‖₂ / ‖p‖₂`` (Eq. 5.7) over the 1269 Munsell chips under D65 for 3, 6
and 9 Gaussian sensors.

The extension (:func:`run_extension`) sweeps n = 3..12, a 2800 K Planckian and a fluorescent
(FL11) illuminant besides D65, the SFU reflectances when a data directory is configured, and
measures the colour error left by the thesis' two-pass method: six diagonal channels projected
back to colour by a linear regression fitted over the reflectances, in CIEDE2000 against the
exact spectral colour (Lab relative to the D65 white).

- :mod:`.compute`: settings, results and the numbers (the errors themselves are
  :func:`spectrinsic.spectra.one_bounce_errors` and :func:`spectrinsic.spectra.two_bounce_errors`);
- :mod:`.report`: text tables and the JSON/CSV/PNG files;
- :mod:`.plot`: the figures.
"""

from .compute import (
    THESIS_TABLE_5_2,
    ErrorRow,
    ExtensionResult,
    TableResult,
    reconstruction_table,
    reflectance_matrix,
    run_extension,
)
from .delta_e import DeltaERow, delta_e_rows
from .plot import extension_figure, table_figure
from .report import format_extension, format_table, write_extension_outputs, write_table_outputs
from .settings import ExtensionSettings, ReconstructionSettings

__all__ = [
    "THESIS_TABLE_5_2",
    "ReconstructionSettings",
    "ExtensionSettings",
    "ErrorRow",
    "DeltaERow",
    "TableResult",
    "ExtensionResult",
    "reflectance_matrix",
    "delta_e_rows",
    "reconstruction_table",
    "format_table",
    "run_extension",
    "format_extension",
    "write_table_outputs",
    "write_extension_outputs",
    "table_figure",
    "extension_figure",
]
