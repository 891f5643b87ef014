"""Figures of the reconstruction-error study (matplotlib's object API: no pyplot, no backend).

Each function returns a :class:`matplotlib.figure.Figure`; :mod:`.report` saves it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .compute import THESIS_TABLE_5_2, ExtensionResult, TableResult

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["table_figure", "extension_figure"]


def table_figure(result: TableResult) -> Figure:
    """Box plots of ε (%, Eq. 5.7, log scale) by number of sensors, one and two bounces, with
    the thesis' mean and max (Table 5.2) marked."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 4), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, b in zip(axes, (1, 2)):
        counts = [n for n in result.settings.sensor_counts if (n, b) in result.errors]
        if not counts:
            ax.set_visible(False)
            continue
        data = [np.clip(result.errors[(n, b)], 1e-4, None) for n in counts]
        ax.boxplot(data, whis=(0, 100), showmeans=True)
        ax.set_xticks(range(1, len(counts) + 1), [str(n) for n in counts])
        for x, n in enumerate(counts, start=1):
            ref = THESIS_TABLE_5_2.get((n, b))
            if ref is not None:
                ax.plot(
                    [x, x],
                    [ref[0], ref[2]],
                    "r_",
                    markersize=14,
                    label="thesis mean / max" if x == 1 else None,
                )
        ax.set_yscale("log")
        ax.set_xlabel("number of Gaussian sensors")
        ax.set_ylabel("reconstruction error ε (%)")
        ax.set_title(
            f"{'one bounce' if b == 1 else 'two bounces'} ({result.settings.reflectances}, "
            f"{result.settings.illuminant})"
        )
        ax.legend(loc="upper right")
    return fig


def extension_figure(result: ExtensionResult) -> Figure:
    """Mean ε (%, log scale) against the number of sensors: a line per reflectance set (style)
    and light (colour), one and two bounces."""
    from matplotlib import rcParams
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 4.2), layout="constrained")
    axes = fig.subplots(1, 2)
    styles = ["-", "--", ":"]
    colours = rcParams["axes.prop_cycle"].by_key()["color"]
    families = list(dict.fromkeys(r.reflectances for r in result.rows))
    lights = list(dict.fromkeys(r.illuminant for r in result.rows))
    for ax, b in zip(axes, (1, 2)):
        for fi, fam in enumerate(families):
            for li, light in enumerate(lights):
                sel = sorted(
                    (r.n_sensors, r.mean_pct)
                    for r in result.rows
                    if r.bounces == b and r.reflectances == fam and r.illuminant == light
                )
                if sel:
                    x, y = zip(*sel)
                    ax.plot(
                        x,
                        y,
                        styles[fi % 3],
                        color=colours[li % len(colours)],
                        marker="o",
                        ms=3,
                        label=f"{fam}, {light}",
                    )
        ax.set_yscale("log")
        ax.set_xlabel("number of Gaussian sensors")
        ax.set_ylabel("mean ε (%)")
        ax.set_title("one bounce" if b == 1 else "two bounces (interreflection)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    return fig
