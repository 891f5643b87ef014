"""Painting parts: repaint the faces of a :class:`~spectrinsic.scenes.parts.Part` by where their
centroids lie (bands, stripes, round patches, printed character grids).

Every face keeps one exact spectrum, so painted regions have sharp edges along face boundaries
(no texture filtering or blending). Units: metres.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..errors import SceneError
from .parts import Part

__all__ = ["bands", "stripes", "patches", "printed"]


def _repaint(part: Part, new: np.ndarray) -> Part:
    """Faces where *new* (an ``(F,)`` object array) is not None take that spectrum."""
    names = part.face_spectra
    keep = np.array([n is None for n in new], dtype=bool)
    names = np.where(keep, names, new)
    palette = tuple(dict.fromkeys(names.tolist()))
    lookup = {n: i for i, n in enumerate(palette)}
    return Part(
        part.vertices, part.faces, np.array([lookup[n] for n in names], dtype=np.int64), palette
    )


def bands(part: Part, spectra: Sequence[str | None], *, axis: int, edges: Sequence[float]) -> Part:
    """Paint bands along *axis*: faces with centroid coordinate in ``[edges[i-1], edges[i])``.

    *spectra* has ``len(edges) + 1`` entries (below the first edge, between edges, above the
    last); ``None`` leaves a band as it was.
    """
    if len(spectra) != len(edges) + 1:
        raise SceneError(
            f"bands needs len(edges) + 1 = {len(edges) + 1} spectra, got {len(spectra)}"
        )
    band = np.searchsorted(
        np.asarray(edges, dtype=np.float64), part.centroids[:, axis], side="right"
    )
    return _repaint(part, np.asarray(list(spectra), dtype=object)[band])


def stripes(
    part: Part, spectra: Sequence[str | None], *, axis: int, width: float, offset: float = 0.0
) -> Part:
    """Paint periodic stripes of *width* along *axis*, cycling through *spectra*."""
    k = np.floor((part.centroids[:, axis] - offset) / width).astype(np.int64) % len(spectra)
    return _repaint(part, np.asarray(list(spectra), dtype=object)[k])


def patches(part: Part, spectrum: str, centres: Sequence[Sequence[float]], radius: float) -> Part:
    """Paint the faces whose centroid lies within *radius* of any of *centres*."""
    c = np.asarray(centres, dtype=np.float64).reshape(-1, 3)
    d = np.linalg.norm(part.centroids[:, None, :] - c[None], axis=-1).min(axis=1)
    new = np.full(len(part.faces), None, dtype=object)
    new[d <= radius] = spectrum
    return _repaint(part, new)


def printed(
    part: Part,
    rows: Sequence[str],
    legend: Mapping[str, str],
    *,
    origin: Sequence[float],
    cell: float,
    axes: tuple[int, int] = (0, 1),
    facing: Sequence[float] = (0.0, 0.0, 1.0),
) -> Part:
    """Print a character grid onto the faces that face *facing* (like ink on paper).

    Row 0 of *rows* is printed at the largest coordinate along ``axes[1]`` (text reads top to
    bottom), column 0 at *origin* along ``axes[0]``; each character covers a square *cell*.
    Characters in *legend* are inked with their spectrum; any other (``" "``, ``"."``) leaves
    the face unchanged.

    >>> from spectrinsic.scenes.primitives import box
    >>> p = printed(box((1, 1, 1), "flat:0.8", divisions=(2, 2, 1)), ["R."], {"R": "flat:0.1"},
    ...             origin=(-0.5, -0.5), cell=0.5)
    >>> sorted(set(p.face_spectra))
    ['flat:0.1', 'flat:0.8']
    """
    u_ax, v_ax = axes
    cen = part.centroids
    up = part.normals @ (np.asarray(facing, dtype=np.float64) / np.linalg.norm(facing)) > 0.9
    col = np.floor((cen[:, u_ax] - origin[0]) / cell).astype(np.int64)
    row = len(rows) - 1 - np.floor((cen[:, v_ax] - origin[1]) / cell).astype(np.int64)
    new = np.full(len(part.faces), None, dtype=object)
    for f in np.flatnonzero(up & (row >= 0) & (row < len(rows)) & (col >= 0)):
        line = rows[row[f]]
        if col[f] < len(line) and line[col[f]] in legend:
            new[f] = legend[line[col[f]]]
    return _repaint(part, new)
