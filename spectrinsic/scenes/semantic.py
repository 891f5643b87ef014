"""Semantic classes: the one class table, and the mapping from names to classes.

Every mesh of a :class:`~spectrinsic.scenes.model.Scene` carries one class of
:data:`SEMANTIC_CLASSES` (:attr:`~spectrinsic.scenes.model.Mesh.semantic`); the ``semantic``
ground-truth layer holds, per pixel, the class id (the index in :data:`SEMANTIC_CLASSES`) of the
object the pixel's first hits mostly see (-1 background), and every sample lists the table
(:func:`class_table`) in ``meta.json`` as ``semantic_classes``.

The scene generators give their meshes their classes. A scene file's meshes take theirs from
their names through a :class:`SemanticMap`: ordered regular expressions → class, searched
case-insensitively in the object name, then in the mesh's material names, else the map's
fallback (``object``). The default map is package data (``semantic_map.yaml`` beside this
module); a user's map (``--semantic-map FILE``, :func:`read_semantic_map`) is tried first.
A mesh's name decides before its materials' names, whichever map's rule matches it.

>>> classify(["floor_lamp"]), classify(["Cube.001", "Oak table top"]), classify(["Mesh.7"])
('lamp', 'table', 'object')
>>> class_id("wall"), class_table()["0"]
(0, 'wall')
"""

from __future__ import annotations

import functools
import os
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from ..errors import SceneError, did_you_mean
from .yaml_limits import load_yaml_file, load_yaml_text

__all__ = [
    "SEMANTIC_CLASSES",
    "FALLBACK_CLASS",
    "SemanticRule",
    "SemanticMap",
    "SemanticRules",
    "class_id",
    "class_table",
    "classify",
    "default_map",
    "read_semantic_map",
    "rules_from_record",
]

#: The class table: a class's id is its index (stable across datasets; new classes are appended).
#: ``unlabelled`` is for meshes a user's map declares unknown; the fallback is ``object``.
SEMANTIC_CLASSES: tuple[str, ...] = (
    "wall",
    "floor",
    "ceiling",
    "table",
    "chair",
    "shelf",
    "sofa",
    "lamp",
    "cabinet",
    "object",
    "window",
    "unlabelled",
)
#: The class of a name no rule matches (unless a map names another fallback).
FALLBACK_CLASS = "object"
#: Most rules in a map file, and longest pattern (characters).
MAX_RULES, MAX_PATTERN = 1000, 500
_FORMAT = 1


def class_id(name: str) -> int:
    """The id of class *name* (its index in :data:`SEMANTIC_CLASSES`); SceneError if unknown."""
    if name not in SEMANTIC_CLASSES:
        raise SceneError(
            f"unknown semantic class {name!r}; expected one of {', '.join(SEMANTIC_CLASSES)}"
            + did_you_mean(name, SEMANTIC_CLASSES)
        )
    return SEMANTIC_CLASSES.index(name)


def class_table() -> dict[str, str]:
    """``{"id": "class"}`` of every class, as samples and manifests record it."""
    return {str(i): name for i, name in enumerate(SEMANTIC_CLASSES)}


@dataclass(frozen=True)
class SemanticRule:
    """A compiled pattern (searched case-insensitively) and the class of names it matches."""

    pattern: re.Pattern[str]
    semantic: str


@dataclass(frozen=True)
class SemanticMap:
    """Ordered rules and the fallback class; :meth:`extended` puts another map's rules first."""

    rules: tuple[SemanticRule, ...]
    fallback: str = FALLBACK_CLASS

    def match(self, name: str) -> str | None:
        """The class of the first rule whose pattern occurs in *name*, else None."""
        return next((r.semantic for r in self.rules if r.pattern.search(name)), None)

    def extended(self, first: SemanticMap, fallback: str | None = None) -> SemanticMap:
        """This map with *first*'s rules tried before its own, and *fallback* if given."""
        return SemanticMap(first.rules + self.rules, fallback or self.fallback)


@dataclass(frozen=True)
class SemanticRules:
    """A map file's content as plain data (what a build's config records): ordered
    ``(regex, class)`` pairs and the fallback class (None: keep the default's)."""

    rules: tuple[tuple[str, str], ...] = ()
    fallback: str | None = None

    def record(self) -> dict[str, object]:
        """As plain JSON (a build's ``source`` records it; :func:`rules_from_record` reads it)."""
        return {"rules": [list(r) for r in self.rules], "fallback": self.fallback}

    def compiled(self) -> SemanticMap:
        """The default map with these rules tried first (and this fallback, if any)."""
        own = SemanticMap(
            tuple(SemanticRule(re.compile(p, re.IGNORECASE), c) for p, c in self.rules)
        )
        return default_map().extended(own, self.fallback)


def _parse(document: object, source: str) -> SemanticRules:
    """The validated rules of a parsed map document (one-line SceneError naming *source*)."""
    if not isinstance(document, Mapping) or set(document) - {"format", "fallback", "rules"}:
        raise SceneError(f"{source}: expected a mapping with keys format, rules and fallback")
    if document.get("format", _FORMAT) != _FORMAT:
        raise SceneError(f"{source}: format {document.get('format')!r}; expected {_FORMAT}")
    rules = document.get("rules") or {}
    if not isinstance(rules, Mapping) or len(rules) > MAX_RULES:
        raise SceneError(f"{source}: rules: expected a mapping of at most {MAX_RULES} regex: class")
    pairs = []
    for pattern, semantic in rules.items():
        if not isinstance(pattern, str) or not pattern or len(pattern) > MAX_PATTERN:
            raise SceneError(
                f"{source}: rule {pattern!r}: expected a regex of 1-{MAX_PATTERN} chars"
            )
        try:
            class_id(str(semantic))
            re.compile(pattern)
        except (re.error, SceneError) as exc:
            raise SceneError(f"{source}: rule {pattern!r}: {exc}") from None
        pairs.append((pattern, str(semantic)))
    fallback = document.get("fallback")
    if fallback is not None:
        try:
            class_id(str(fallback))
        except SceneError as exc:
            raise SceneError(f"{source}: fallback: {exc}") from None
    return SemanticRules(tuple(pairs), None if fallback is None else str(fallback))


@functools.cache
def default_map() -> SemanticMap:
    """The shipped map (``semantic_map.yaml``), read once."""
    text = resources.files(__package__).joinpath("semantic_map.yaml").read_text("utf-8")
    parsed = _parse(load_yaml_text(text, "semantic_map.yaml"), "semantic_map.yaml")
    rules = tuple(SemanticRule(re.compile(p, re.IGNORECASE), c) for p, c in parsed.rules)
    return SemanticMap(rules, parsed.fallback or FALLBACK_CLASS)


def rules_from_record(record: object, source: str = "semantic_map") -> SemanticRules:
    """The :class:`SemanticRules` of their :meth:`~SemanticRules.record` (validated again)."""
    if not isinstance(record, Mapping) or not isinstance(record.get("rules"), list):
        raise SceneError(f"{source}: expected {{rules: [[regex, class], ...], fallback}}")
    pairs = {}
    for pair in record["rules"]:
        if not isinstance(pair, list) or len(pair) != 2:
            raise SceneError(f"{source}: rules: expected [regex, class] pairs, got {pair!r}")
        pairs[pair[0]] = pair[1]
    return _parse({"rules": pairs, "fallback": record.get("fallback")}, source)


def read_semantic_map(path: str | os.PathLike[str]) -> SemanticRules:
    """The rules of the user's map file *path* (YAML or JSON, the form of
    ``semantic_map.yaml``: ``rules``, regex: class in order, and an optional ``fallback``),
    validated; :meth:`SemanticRules.compiled` puts them before the default rules. One-line
    :class:`SceneError` naming the file on bad input."""
    if not Path(path).is_file():
        raise SceneError(f"{path}: semantic map not found (expected a YAML or JSON file)")
    return _parse(load_yaml_file(path), str(path))


def classify(names: Iterable[str], semantic_map: SemanticMap | None = None) -> str:
    """The class of the first of *names* (object name, then material names) some rule of
    *semantic_map* (default: :func:`default_map`) matches; else the map's fallback."""
    chosen = semantic_map or default_map()
    return next(
        (c for c in (chosen.match(n) for n in names) if c is not None),
        chosen.fallback,
    )
