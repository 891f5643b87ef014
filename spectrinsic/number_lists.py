"""Lists of plain numbers inside plain data, recognised whole instead of value by value.

A scene record (``scene.json``) is mostly mesh data: a 256² room holds about 110,000 vertex
coordinates and face indices, as lists of ``[x, y, z]`` rows. The walkers over plain data
(:func:`~spectrinsic.gt_export.sample.plain_data`, the ``csv:`` name walkers of
:mod:`~spectrinsic.spectra.user_spectra` and :mod:`~spectrinsic.gt_export.relight`) change only
strings, mappings and non-plain values, never a plain number; so a list holding nothing but
numbers, or rows of them, is copied as it is (:func:`copy_numbers`) after one test of its item
types in C (:func:`numbers_only`), not walked with a Python call per value. The output is the
same as the walk's, value for value (its rows may be the input's own lists).
"""

from __future__ import annotations

import itertools
import math
from typing import Any

__all__ = ["numbers_only", "finite_numbers", "copy_numbers"]

#: The exact types of a plain number (``type(x)``, not ``isinstance``: a numpy scalar or another
#: subclass is not plain and goes through the walk, which converts it).
_NUMBER_TYPES = frozenset({int, float, bool})


def _is_rows(kinds: set[type]) -> bool:
    return kinds == {list} or kinds == {tuple}


def numbers_only(value: list[Any] | tuple[Any, ...]) -> bool:
    """Whether *value* holds plain numbers only (``int``, ``float``, ``bool``), directly or in
    rows of one kind (all lists or all tuples) one level down, as a mesh's vertices and faces.

    >>> numbers_only([[0.5, 1, True], [2.0, 3, 4]]), numbers_only([1, "csv:a.csv#x"])
    (True, False)
    >>> numbers_only([[1, 2], [3, [4]]]), numbers_only([]), numbers_only([[]])
    (False, True, True)
    """
    kinds = set(map(type, value))
    if kinds <= _NUMBER_TYPES:
        return True
    return _is_rows(kinds) and set(map(type, itertools.chain.from_iterable(value))) <= _NUMBER_TYPES


def finite_numbers(value: list[Any] | tuple[Any, ...]) -> bool:
    """Whether the plain numbers of *value* (:func:`numbers_only`) are all finite: their sum is
    (a NaN or an infinity makes it NaN or infinite). A sum that overflows answers ``False`` for
    finite values too, which only sends them through the walk.

    >>> finite_numbers([[1.0, 2], [3, 4]]), finite_numbers([1.0, float("nan")])
    (True, False)
    >>> finite_numbers([1e308, 1e308]), finite_numbers([10**400])
    (False, False)
    """
    flat = itertools.chain.from_iterable(value) if _is_rows(set(map(type, value))) else value
    try:
        return math.isfinite(sum(flat, 0.0))
    except OverflowError:  # an int beyond float's range
        return False


def copy_numbers(value: list[Any] | tuple[Any, ...]) -> list[Any]:
    """A list copy of *value* (:func:`numbers_only`) whose rows are lists, as the walk makes
    them: rows that are lists already are shared, not copied (plain data is read and written,
    never changed in place; allocating 20,000 rows again costs more than the walk saved, as
    each allocation can start a garbage collection over the whole record).

    >>> copy_numbers(((1, 2), (3, 4)))
    [[1, 2], [3, 4]]
    >>> rows = [[1, 2]]; copy_numbers(rows)[0] is rows[0]
    True
    """
    if value and set(map(type, value)) == {tuple}:
        return [list(row) for row in value]
    return list(value)
