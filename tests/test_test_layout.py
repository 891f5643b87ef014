"""Tests mirror the package (issue 46): a test file lives in ``tests/<path>/`` when it guards a
module of ``spectrinsic/<path>/``.

What is checked, from each test module's imports of the package (names imported through a
package's ``__init__`` are followed to the module that defines them):

* every folder of ``tests/`` below the root mirrors a folder of the package;
* a test file in ``tests/<path>/`` that imports modules of its top package (the wing:
  ``spectrinsic.gt_export`` for ``tests/gt_export/layers/``) imports at least one module of
  ``spectrinsic.<path>`` (it guards something here, not only in a neighbouring folder), unless
  it drives the command line (``spectrinsic.cli``);
* a test file in ``tests/<path>/`` whose imports of ``spectrinsic.<path>`` all lie in one
  subfolder ``<sub>`` belongs in ``tests/<path>/<sub>/`` (no flat folder mixing wings).

A test that drives the command line (``spectrinsic.cli``) may name no module of its folder: it
is placed by its subject. ``importlib.import_module("spectrinsic....")`` counts as an import.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TESTS = ROOT / "tests"
PACKAGE = "spectrinsic"


def _is_package(module: str) -> bool:
    return ROOT.joinpath(*module.split("."), "__init__.py").is_file()


def _is_module(module: str) -> bool:
    return _is_package(module) or ROOT.joinpath(*module.split(".")).with_suffix(".py").is_file()


def _face_source(package: str, name: str, depth: int = 0) -> str:
    """The module that defines *name* re-exported by *package*'s ``__init__`` (followed through
    relative ``from .x import name`` lines), or *package* itself."""
    init = ROOT.joinpath(*package.split("."), "__init__.py")
    for node in ast.parse(init.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.ImportFrom) and node.level == 1 and node.module:
            if any((a.asname or a.name) == name for a in node.names):
                source = f"{package}.{node.module}"
                if _is_package(source) and depth < 4:
                    return _face_source(source, name, depth + 1)
                return source
    return package


def _dynamic_import(node: ast.AST) -> bool:
    """Whether *node* is ``importlib.import_module("spectrinsic...")`` (a module whose name the
    package's face shadows, as ``gt_export.relight`` by the function ``relight``)."""
    return (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Attribute)
        and node.func.attr == "import_module"
        and len(node.args) == 1
        and isinstance(node.args[0], ast.Constant)
        and str(node.args[0].value).split(".")[0] == PACKAGE
    )


def imported_modules(source: str) -> set[str]:
    """The package modules a test module imports, re-exports followed to their definitions."""
    found: set[str] = set()
    for node in ast.walk(ast.parse(source)):
        if _dynamic_import(node):
            found.add(node.args[0].value)  # type: ignore[attr-defined]
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.split(".")[0] == PACKAGE}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            if node.module.split(".")[0] != PACKAGE:
                continue
            for alias in node.names:
                full = f"{node.module}.{alias.name}"
                if _is_module(full):
                    found.add(full)
                elif _is_package(node.module):
                    found.add(_face_source(node.module, alias.name))
                else:
                    found.add(node.module)
    return found


def misplaced(folder: str, modules: set[str]) -> str | None:
    """Why a test file in ``tests/<folder>/`` importing *modules* is in the wrong folder, or
    ``None``. *folder* is ``/``-separated (``gt_export/layers``)."""
    here = f"{PACKAGE}.{folder.replace('/', '.')}"
    wing = folder.split("/")[0]
    ours = {m for m in modules if m.startswith(f"{PACKAGE}.{wing}.") or m == f"{PACKAGE}.{wing}"}
    if not ours:
        return None  # a command-line test, or one of the package as a whole
    inside = {m for m in ours if m == here or m.startswith(here + ".")}
    if not inside and not any(m.startswith(f"{PACKAGE}.cli") for m in modules):
        return f"imports no module of {here} (it imports {sorted(ours)})"
    subs = {m[len(here) + 1 :].split(".")[0] for m in inside if m != here}
    sub = f"{here}.{next(iter(subs))}" if len(subs) == 1 and here not in inside else None
    if sub is not None and _is_package(sub):
        return f"imports only {sub}: move it to tests/{folder}/{sub.rpartition('.')[2]}/"
    return None


def _test_modules() -> Iterator[tuple[str, Path]]:
    """``(folder relative to tests/, path)`` of every test module below ``tests/<package>/``."""
    for path in sorted(TESTS.rglob("test_*.py")):
        rel = path.parent.relative_to(TESTS)
        if rel.parts:
            yield "/".join(rel.parts), path


def test_the_rule_finds_a_misplaced_file():
    """A flat file guarding one subfolder, and a file in a subfolder it does not guard, are
    found; a file guarding two subfolders, or only the command line, is left where it is."""
    layers = f"{PACKAGE}.gt_export.layers.compose"
    formats = f"{PACKAGE}.gt_export.formats.exr"
    assert "move it to tests/gt_export/layers/" in (misplaced("gt_export", {layers}) or "")
    assert misplaced("gt_export", {layers, formats}) is None
    assert misplaced("gt_export/layers", {layers, formats}) is None
    assert "imports no module" in (misplaced("gt_export/formats", {layers}) or "")
    assert misplaced("gt_export/formats", {f"{PACKAGE}.cli"}) is None
    assert misplaced("gt_export/formats", {layers, f"{PACKAGE}.cli"}) is None
    code = f'import importlib\nm = importlib.import_module("{PACKAGE}.gt_export.relight")\n'
    assert imported_modules(code) == {f"{PACKAGE}.gt_export.relight"}
    assert imported_modules(f"from {PACKAGE}.gt_export import compute_ground_truth\n") == {layers}


def test_every_test_folder_mirrors_a_package_folder():
    folders = {folder for folder, _ in _test_modules()}
    assert len(folders) > 10  # the scan sees the tests
    wrong = sorted(f for f in folders if not _is_package(f"{PACKAGE}.{f.replace('/', '.')}"))
    assert wrong == [], f"test folders with no package folder of that path: {wrong}"


def test_every_test_file_lives_in_the_folder_of_what_it_guards():
    wrong = []
    for folder, path in _test_modules():
        why = misplaced(folder, imported_modules(path.read_text(encoding="utf-8")))
        if why is not None:
            wrong.append(f"{path.relative_to(ROOT)}: {why}")
    assert wrong == [], "test files outside the folder of the module they guard:\n" + "\n".join(
        wrong
    )
