"""Exceptions and warnings raised by spectrinsic.

Every error raised for bad user input is a :class:`SpectrinsicError` whose message is one line
that names the input and what was expected. Suspicious but valid input gives a
:class:`SpectrinsicWarning`.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable

__all__ = [
    "SpectrinsicError",
    "SpectrumNotFoundError",
    "DataDirectoryError",
    "SpectralDataError",
    "SceneError",
    "RenderError",
    "DatasetError",
    "SampleMetaError",
    "WorkingSpaceError",
    "WriteError",
    "DiskFullError",
    "DecomposeError",
    "StudyError",
    "MissingDependencyError",
    "SpectrinsicWarning",
    "validate_choice",
    "with_article",
    "did_you_mean",
]


class SpectrinsicError(Exception):
    """Base class of every error spectrinsic raises for bad input or missing resources."""


class SpectrumNotFoundError(SpectrinsicError, KeyError):
    """A spectrum, sensor set or illuminant name that no registry knows."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class DataDirectoryError(SpectrinsicError, FileNotFoundError):
    """A spectral data directory is not configured or lacks an expected file."""


class SpectralDataError(SpectrinsicError, ValueError):
    """Spectral values or wavelengths that are malformed (empty, non-increasing, negative...)."""


class SceneError(SpectrinsicError, ValueError):
    """A scene description that is malformed or physically meaningless."""


class RenderError(SpectrinsicError, RuntimeError):
    """Rendering could not be carried out (no usable Mitsuba variant, failed pass...)."""


class DatasetError(SpectrinsicError, RuntimeError):
    """A dataset folder that is incomplete, corrupt or inconsistent with its manifest."""


class SampleMetaError(DatasetError):
    """A sample's ``meta.json`` that cannot be trusted: not JSON, a field missing, misnamed or of
    the wrong type, a non-finite number, or content that no longer matches its seal. The message
    names the file and the field."""


class WorkingSpaceError(DatasetError, ValueError):
    """An RGB working space name no table knows (``--working-space``, a dataset config,
    ``meta.json["working_space"]``); raised by :func:`spectrinsic.spectra.working_space.working_space`,
    the one place a name is checked."""


class WriteError(DatasetError):
    """An output file that could not be written (permission denied, read-only file system...)."""


class FolderLockedError(DatasetError):
    """Another spectrinsic run holds the advisory lock of the folder this run would write."""


class DiskFullError(WriteError):
    """No space left (``ENOSPC``, ``EDQUOT``): every further sample would fail the same way,
    so a dataset build stops at the first one."""


class DecomposeError(SpectrinsicError, ValueError):
    """A decomposer, metric or decomposition setting that is unknown or given a parameter it
    does not take."""


class StudyError(SpectrinsicError, ValueError):
    """A study setting that is unknown (a camera balance, a fit scope, a quality preset...)."""


class MissingDependencyError(SpectrinsicError, ImportError):
    """An optional dependency needed by the requested feature is not installed."""


class SpectrinsicWarning(UserWarning):
    """Suspicious but valid input, or a degraded mode (e.g. scalar Mitsuba variants)."""


def did_you_mean(value: str, choices: Iterable[str], n: int = 3) -> str:
    """Return ``" (did you mean 'a', 'b'?)"`` for close matches of *value*, or ``""``; letter
    case aside (``RGB3`` is close to ``rgb3``)."""
    by_lower = {c.lower(): c for c in choices}
    close = [
        by_lower[c] for c in difflib.get_close_matches(value.lower(), by_lower, n=n, cutoff=0.6)
    ]
    if not close:
        return ""
    return " (did you mean " + ", ".join(repr(c) for c in close) + "?)"


def with_article(word: str) -> str:
    """*word* with its indefinite article, for messages.

    >>> with_article("area"), with_article("reflectance"), with_article("illuminant")
    ('an area', 'a reflectance', 'an illuminant')
    """
    return f"{'an' if word[:1].lower() in 'aeiou' else 'a'} {word}"


def validate_choice(
    value: str,
    choices: Iterable[str],
    what: str,
    *,
    error: type[SpectrinsicError] = SpectrinsicError,
) -> str:
    """Return *value* if it is one of *choices*, else raise a one-line *error*.

    Parameters
    ----------
    value
        The name given by the user.
    choices
        The valid names, in the order the message lists them.
    what
        What the name names, for the message (``"render mode"``).
    error
        The :class:`SpectrinsicError` subclass raised, so the error belongs to the caller's
        domain (``SceneError`` in :mod:`spectrinsic.scenes`, ``RenderError`` in
        :mod:`spectrinsic.render`...).

    >>> validate_choice("rgb3", ["rgb3", "rgb6"], "render mode")
    'rgb3'
    >>> validate_choice("rgb4", ["rgb3", "rgb6"], "render mode", error=SceneError)
    Traceback (most recent call last):
    ...
    spectrinsic.errors.SceneError: unknown render mode 'rgb4'; expected one of 'rgb3', 'rgb6' (did you mean 'rgb6', 'rgb3'?)
    """
    choices = list(choices)
    if value in choices:
        return value
    raise error(
        f"unknown {what} {value!r}; expected one of {', '.join(map(repr, choices))}"
        + did_you_mean(value, choices)
    )
