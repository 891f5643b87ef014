"""YAML read with limits: file size, node count, nesting depth, alias expansion, and no
duplicate keys.

``yaml.safe_load`` blocks Python object tags but not resource exhaustion: a 1.2 KB "billion
laughs" alias bomb expands to hundreds of millions of nodes, a 5000-deep nested list overflows
the composer's recursion, and a duplicated key silently keeps the last value. This loader
refuses each of them with a one-line :class:`~spectrinsic.errors.SceneError` naming the file
and line, before anything is built from the document.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import yaml

from ..errors import SceneError

__all__ = ["MAX_YAML_BYTES", "MAX_DEPTH", "MAX_NODES", "load_yaml_file", "load_yaml_text"]

#: Largest scene file read (large meshes belong in PLY files next to it, see FORMAT.md).
MAX_YAML_BYTES = 16 * 2**20
#: Deepest nesting of lists and mappings (a scene needs 4: meshes[i].vertices[j][k]).
MAX_DEPTH = 64
#: Most nodes, counted twice: as the composer builds them (so memory stays bounded while the
#: file is read: PyYAML's nodes take about 1 KiB each, measured 207 MiB peak for 200,000) and
#: again after expanding every alias, each use counted (far below an alias bomb). Enough for an
#: inline mesh of about 100,000 vertices; larger meshes belong in PLY files (FORMAT.md).
MAX_NODES = 500_000


class _LimitedLoader(yaml.SafeLoader):
    """SafeLoader that bounds nesting and alias expansion and rejects duplicate keys."""

    def __init__(self, stream: str, source: str) -> None:
        super().__init__(stream)
        self.source = source
        self._depth = 0
        self._composed = 0

    def _fail(self, node: yaml.Node | None, problem: str) -> SceneError:
        line = f"line {node.start_mark.line + 1}: " if node is not None else ""
        return SceneError(f"{self.source}: {line}{problem}")

    def compose_node(self, parent: Any, index: Any) -> Any:
        self._depth += 1
        self._composed += 1
        try:
            if self._composed > MAX_NODES:
                mark = self.peek_event().start_mark
                raise SceneError(
                    f"{self.source}: line {mark.line + 1}: more than {MAX_NODES:,} YAML "
                    "nodes; put large meshes in PLY files (FORMAT.md)"
                )
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise SceneError(
                    f"{self.source}: line {mark.line + 1}: nesting deeper than {MAX_DEPTH} levels"
                )
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def compose_document(self) -> Any:
        node = super().compose_document()
        _expanded_size(node, {}, self)
        return node

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue  # `<<: *base` then overriding a key is what merge keys are for
            key = self.construct_object(key_node, deep=True)
            try:
                duplicate = key in seen
                seen.add(key)
            except TypeError:  # an unhashable key: SafeLoader reports it itself
                continue
            if duplicate:
                raise self._fail(key_node, f"duplicate key {key!r}; each key may appear once")
        return super().construct_mapping(node, deep=deep)


def _expanded_size(node: yaml.Node, memo: dict[int, int], loader: _LimitedLoader) -> int:
    """Nodes in *node* with every alias expanded (memoised, so linear in the document)."""
    key = id(node)
    if key in memo:
        if memo[key] < 0:
            raise loader._fail(node, "a recursive alias (an anchor used inside itself)")
        return memo[key]
    memo[key] = -1  # in progress: meeting it again means a cycle
    size = 1
    if isinstance(node, yaml.SequenceNode):
        size += sum(_expanded_size(child, memo, loader) for child in node.value)
    elif isinstance(node, yaml.MappingNode):
        size += sum(
            _expanded_size(k, memo, loader) + _expanded_size(v, memo, loader) for k, v in node.value
        )
    if size > MAX_NODES:
        raise loader._fail(
            node, f"aliases expand to more than {MAX_NODES:,} nodes; refusing (an alias bomb?)"
        )
    memo[key] = size
    return size


def _invalid(exc: yaml.YAMLError, source: str) -> SceneError:
    """One line for a YAML error: the line (or the character position) and the problem."""
    mark = getattr(exc, "problem_mark", None)
    position = getattr(exc, "position", None)  # a ReaderError: a character not allowed
    if mark is not None:
        where = f"line {mark.line + 1}"
    elif isinstance(position, int):
        where = f"character {position}"
    else:
        where = "YAML"
    problem = " ".join(
        str(getattr(exc, "problem", None) or getattr(exc, "reason", None) or exc).split()
    )
    character = getattr(exc, "character", None)  # a ReaderError's code point (or character)
    if isinstance(character, str) and len(character) == 1:
        character = ord(character)
    if isinstance(character, int):
        problem = f"character #x{character:04x}: {problem}"
    return SceneError(f"{source}: {where}: invalid YAML ({problem})")


def load_yaml_text(text: str, source: str) -> Any:
    """Parse *text* with the limits above; *source* names it in errors."""
    if len(text) > MAX_YAML_BYTES:
        raise SceneError(
            f"{source}: {len(text):,} characters; scene files are limited to "
            f"{MAX_YAML_BYTES:,} (put large meshes in PLY files)"
        )
    rough = text.count(",") + text.count("- ") + text.count(": ")
    if rough > MAX_NODES:  # composing them first would take minutes (pure-Python PyYAML)
        raise SceneError(
            f"{source}: about {rough:,} YAML values (counted from commas, list items "
            f"and keys), more than {MAX_NODES:,}; put large meshes in PLY files (FORMAT.md)"
        )
    try:
        loader = _LimitedLoader(text, source)  # the reader refuses control characters here
    except yaml.YAMLError as exc:
        raise _invalid(exc, source) from exc
    try:
        return loader.get_single_data()
    except yaml.YAMLError as exc:
        raise _invalid(exc, source) from exc
    except RecursionError as exc:  # a construct deeper than the checks foresaw
        raise SceneError(f"{source}: nesting too deep to read") from exc
    finally:
        loader.dispose()


def load_yaml_file(path: str | os.PathLike[str]) -> Any:
    """Read and parse a YAML file with the limits above (size checked before reading)."""
    path = Path(path)
    source = str(path)
    try:
        size = path.stat().st_size
        if size > MAX_YAML_BYTES:
            raise SceneError(
                f"{source}: {size:,} bytes; scene files are limited to "
                f"{MAX_YAML_BYTES:,} (put large meshes in PLY files)"
            )
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"{source}: cannot read scene file ({type(exc).__name__}: {exc})") from exc
    return load_yaml_text(text, source)
