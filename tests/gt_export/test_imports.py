"""gt_export's import graph: no cycle (function-level imports included), and the readers of a
sample folder take nothing from its writer."""

from __future__ import annotations

import ast
from pathlib import Path

GT_EXPORT = Path(__file__).resolve().parents[2] / "spectrinsic" / "gt_export"
PACKAGE = "spectrinsic.gt_export"
#: Modules that read sample folders (directly or through the loader).
READERS = (
    "sample",
    "sample.meta",
    "sample.json_fields",
    "sample.integrity",
    "dataset.loader",
    "dataset.check",
    "dataset.gallery",
    "dataset.shards",
    "dataset.manifest",
    "dataset.card",
    "dataset.diversity",
)


def _module_name(path: Path) -> str:
    rel = path.relative_to(GT_EXPORT).with_suffix("")
    parts = [p for p in rel.parts if p != "__init__"]
    return ".".join([PACKAGE, *parts]) if parts else PACKAGE


def _graph() -> dict[str, set[str]]:
    """Module -> the gt_export modules it imports anywhere in its body (not the package init)."""
    modules = {_module_name(p): p for p in GT_EXPORT.rglob("*.py")}
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            targets: list[str] = []
            if isinstance(node, ast.ImportFrom):
                base = _absolute(node, package)
                full = [f"{base}.{a.name}" for a in node.names]  # a module, else a name of base
                targets = [f if f in modules else base for f in full]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            graph[name].update(t for t in targets if t in modules and t not in (PACKAGE, name))
    return graph


def _absolute(node: ast.ImportFrom, package: str) -> str:
    """The module ``from X import ...`` names, relative forms resolved from *package*."""
    if not node.level:
        return node.module or ""
    parts = package.split(".")
    anchor = parts[: len(parts) - node.level + 1]
    return ".".join([*anchor, node.module] if node.module else anchor)


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt) :] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return None


def test_the_cycle_finder_finds_a_cycle():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) is None


def test_gt_export_has_no_import_cycle():
    graph = _graph()
    assert (
        f"{PACKAGE}.layers.compose" in graph and graph[f"{PACKAGE}.dataset.card"]
    )  # the scan sees modules
    assert _cycle(graph) is None


def test_readers_take_nothing_from_the_writer():
    graph = _graph()
    writer = f"{PACKAGE}.sample.writer"
    assert [r for r in READERS if writer in graph[f"{PACKAGE}.{r}"]] == []
