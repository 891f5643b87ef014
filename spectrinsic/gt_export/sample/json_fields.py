"""Typed reading of spectrinsic's JSON records, with errors that name the file and the field.

:class:`JsonFields` is what :mod:`~spectrinsic.gt_export.sample.meta` (``meta.json``) and
:mod:`~spectrinsic.gt_export.dataset.manifest` (``manifest.json``) read their fields through: every
accessor checks one type and, if it does not hold, raises a one-line
:class:`~spectrinsic.errors.SampleMetaError` ``"<file>: <field>: expected <what>, got <value>"``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ...errors import SampleMetaError
from . import confined_path

__all__ = ["JsonFields", "load_json", "reject_constant"]


class JsonFields:
    """Typed access to a parsed ``meta.json`` whose errors name the file and the field."""

    def __init__(self, path: Path) -> None:
        self.path = path
        #: Paths already found inside the folder (a file is named by several layers).
        self._inside: set[str] = set()

    def fail(self, name: str, expected: str, value: object = ...) -> SampleMetaError:
        got = "" if value is ... else f", got {_short(value)}"
        return SampleMetaError(f"{self.path}: {name}: expected {expected}{got}")

    def exact_keys(
        self,
        obj: Mapping[str, Any],
        name: str,
        keys: frozenset[str],
        required: frozenset[str] | None = None,
    ) -> None:
        for key in sorted((keys if required is None else required) - set(obj)):
            raise SampleMetaError(f"{self.path}: {_join(name, key)}: missing")
        for key in sorted(set(obj) - keys):
            raise SampleMetaError(
                f"{self.path}: {_join(name, key)}: not a field spectrinsic writes"
            )

    def mapping(self, value: object, name: str) -> Mapping[str, Any]:
        if not isinstance(value, dict):
            raise self.fail(name, "a JSON object", value)
        return value

    def text(self, value: object, name: str, *, optional: bool = False) -> str:
        if optional and value is None:
            return value  # type: ignore[return-value]
        if not isinstance(value, str):
            raise self.fail(name, "a string" + (" or null" if optional else ""), value)
        return value

    def integer(self, value: object, name: str, *, low: int = 0) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < low:
            raise self.fail(name, f"a whole number >= {low}", value)
        return value

    def number(self, value: object, name: str) -> float:
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not math.isfinite(value)
        ):
            raise self.fail(name, "a finite number", value)
        return float(value)

    def sequence(self, value: object, name: str) -> Sequence[Any]:
        if not isinstance(value, list):
            raise self.fail(name, "a JSON list", value)
        return value

    def texts(self, value: object, name: str) -> tuple[str, ...]:
        return tuple(self.text(v, f"{name}[{i}]") for i, v in enumerate(self.sequence(value, name)))

    def numbers(self, value: object, name: str) -> tuple[float, ...]:
        return tuple(
            self.number(v, f"{name}[{i}]") for i, v in enumerate(self.sequence(value, name))
        )

    def inside(self, value: object, name: str) -> str:
        rel = self.text(value, name)
        if rel not in self._inside:
            if confined_path(self.path.parent, rel) is None:
                raise self.fail(name, "a path inside the sample folder", rel)
            self._inside.add(rel)
        return rel

    def numeric_tree(self, value: object, name: str) -> None:
        """Every leaf of nested objects and lists is a finite number, a string, a bool or null."""
        if isinstance(value, dict):
            for key, item in value.items():
                self.numeric_tree(item, _join(name, key))
        elif isinstance(value, list):
            for i, item in enumerate(value):
                self.numeric_tree(item, f"{name}[{i}]")
        elif value is not None and not isinstance(value, (str, bool)):
            self.number(value, name)


def _join(name: str, key: str) -> str:
    return f"{name}.{key}" if name else key


def _short(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def reject_constant(name: str) -> float:
    raise ValueError(f"non-finite number {name} (spectrinsic writes none)")


def load_json(path: Path) -> Any:
    """The parsed JSON of *path*; a JSON ``NaN``/``Infinity`` is refused (spectrinsic writes none)."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SampleMetaError(f"{path}: cannot be read ({exc.strerror or exc})") from exc
    except ValueError as exc:
        raise SampleMetaError(f"{path}: not UTF-8 text ({exc})") from exc
    try:
        return json.loads(text, parse_constant=reject_constant)
    except (ValueError, RecursionError) as exc:  # RecursionError: nesting too deep
        raise SampleMetaError(f"{path}: not valid JSON ({exc})") from exc
