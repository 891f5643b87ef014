"""The import graph of the whole package: no cycle, and imports inside functions only where the
rule allows them.

**The rule.** A module imports what it needs at its top. An import inside a function is allowed
only for a heavy or optional dependency (:data:`HEAVY`): Mitsuba/Dr.Jit, bpy, torch, Dask,
Selenium, pyoidn, webdataset, the graph-cut wrapper, and the libraries whose import alone costs
about a second or more on the 2-core machine (colour-science, matplotlib, SciPy, scikit-image's
SciPy-backed parts, trimesh). Never to break an import cycle: a cycle is fixed by moving the
shared vocabulary down into a module both sides import. ``if TYPE_CHECKING:`` blocks are not
executed and do not count.

The graph has one node per module of ``spectrinsic/`` and one edge per import statement, *function-level imports included*: a cycle hidden inside a function
is still a cycle (it only moves the failure from import time to the first call).
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE_DIR = ROOT / "spectrinsic"
#: The package's parts: its subpackages, and ``core`` for the modules at its root.
FOLDERS = sorted(
    {p.name for p in PACKAGE_DIR.iterdir() if (p / "__init__.py").is_file()} | {"core"}
)
#: Top-level names that may be imported inside a function (see the module docstring).
HEAVY = frozenset(
    {
        "mitsuba",
        "drjit",
        "bpy",
        "torch",
        "dask",
        "distributed",
        "selenium",
        "pyoidn",
        "webdataset",
        "gco",
        "colour",
        "colour_demosaicing",
        "pidng",
        "matplotlib",
        "scipy",
        "skimage",
        "trimesh",
        "zstandard",
        "OpenEXR",
        "PIL",
    }
)


def module_files() -> Iterator[tuple[str, Path]]:
    """``(module name, path)`` of every module of the package."""
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        yield ".".join(parts), path


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    """ids of the import nodes inside ``if TYPE_CHECKING:`` blocks."""
    skipped: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skipped.update(id(n) for stmt in node.body for n in ast.walk(stmt))
    return skipped


def _function_nodes(tree: ast.AST) -> set[int]:
    """ids of every node inside a function body."""
    inside: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
            inside.update(id(n) for n in ast.walk(node) if n is not node)
    return inside


def imports(module: str, path: Path, modules: set[str]) -> Iterator[tuple[str, bool]]:
    """``(imported module, inside a function)`` for every executed import of *module*, one per
    imported name: ``from A import b`` gives ``A.b`` when that is a module of *modules*, else
    ``A``; relative imports are resolved."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    skipped, inside = _type_checking_nodes(tree), _function_nodes(tree)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(tree):
        if id(node) in skipped:
            continue
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, id(node) in inside
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                anchor = parts[: len(parts) - node.level + 1]
                base = ".".join([*anchor, base]) if base else ".".join(anchor)
            for alias in node.names:
                full = f"{base}.{alias.name}"
                yield (full if full in modules else base), id(node) in inside


def import_graph() -> tuple[dict[str, set[str]], list[tuple[str, str]]]:
    """Edges module -> imported modules of the package, and every function-level import as
    ``(module, imported module)``."""
    files = dict(module_files())
    modules = set(files)
    graph: dict[str, set[str]] = {m: set() for m in files}
    nested: list[tuple[str, str]] = []
    for module, path in files.items():
        for name, in_function in imports(module, path, modules):
            if name in modules and name != module:
                graph[module].add(name)
            if in_function:
                nested.append((module, name))
    return graph, nested


def cycles(graph: dict[str, set[str]]) -> list[frozenset[str]]:
    """The strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[frozenset[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for dep in sorted(graph[node]):
            if dep not in index:
                visit(dep)
                low[node] = min(low[node], low[dep])
            elif dep in on_stack:
                low[node] = min(low[node], index[dep])
        if low[node] == index[node]:
            component = set()
            while True:
                top = stack.pop()
                on_stack.discard(top)
                component.add(top)
                if top == node:
                    break
            if len(component) > 1:
                found.append(frozenset(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return found


def test_the_checker_finds_a_cycle_hidden_in_a_function(tmp_path):
    """The checker sees a function-level import and a relative one."""
    a, b = tmp_path / "a.py", tmp_path / "b.py"
    a.write_text("def f():\n    from spectrinsic.b import g\n")
    b.write_text("from . import a\n")
    graph = {"spectrinsic.a": set(), "spectrinsic.b": set()}
    for module, path in (("spectrinsic.a", a), ("spectrinsic.b", b)):
        graph[module] = {
            n for n, _ in imports(module, path, set(graph)) if n in graph and n != module
        }
    assert cycles(graph) == [frozenset(graph)]
    assert list(imports("spectrinsic.a", a, set(graph))) == [("spectrinsic.b", True)]


def test_no_import_cycle_in_any_package():
    graph, _ = import_graph()
    found = cycles(graph)
    assert not found, "import cycles: " + "; ".join(" <-> ".join(sorted(c)) for c in found)


def test_the_cycle_finder_finds_cycles():
    """The finder the test above relies on: a three-module ring and a two-module cycle are
    found, a chain and a self-import are not."""
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"e"}, "e": {"d", "f"}, "f": set()}
    graph["g"] = {"g"}
    assert sorted(map(sorted, cycles(graph))) == [["a", "b", "c"], ["d", "e"]]


def _folder(module: str) -> str:
    sub = module.split(".")[1] if module.count(".") else ""
    return sub if sub in FOLDERS else "core"


@pytest.mark.parametrize("folder", sorted(FOLDERS))
def test_imports_inside_functions_are_only_heavy_optional_ones(folder):
    _, nested = import_graph()
    wrong = [
        f"{m}: {name}"
        for m, name in nested
        if _folder(m) == folder and name.split(".")[0] not in HEAVY
    ]
    assert not wrong, "imports inside functions (move them to the top):\n" + "\n".join(wrong)


#: Imported names inside functions (one per name): 248 before issue 18, of which 192 of light
#: modules; since then only heavy optional ones (:data:`HEAVY`). A ratchet: lower it. Issue 43
#: added 4 heavy ones: torch (learn/torch_import.py), matplotlib for the training curve and the
#: sim2real figure, scipy for the sim2real t-intervals. Round 5 added 4: bpy and colour in
#: scenes/blender_working_space.py (a .blend's working space and the exact matrix from it to
#: Rec. 709, read only when a .blend is opened), drjit in render/base/sample_split.py (the
#: thread count of a split render, as the other render modules import it) and scipy.ndimage
#: in decompose/methods/shading_texture.py.
MAX_FUNCTION_IMPORTS = 112


def test_function_level_imports_are_counted():
    """The count docs/ARCHITECTURE.md quotes; it may only go down."""
    _, nested = import_graph()
    heavy = [p for p in nested if p[1].split(".")[0] in HEAVY]
    assert len(nested) <= MAX_FUNCTION_IMPORTS, f"{len(nested)} imports inside functions"
    assert len(nested) == len(heavy), "light imports inside functions"
