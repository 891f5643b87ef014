"""Packaging and layering guards: nothing silently left out of the wheel, no wrong-way imports."""

from __future__ import annotations

import ast
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE_DIR = ROOT / "spectrinsic"
#: Data flows one way. The root package's base modules come first; then the data-flow packages;
#: then the top layer (the dataset pipeline, the studies, the benchmarks and the CLI). A module
#: may import its own layer and the layers to its left, never one to its right.
CORE_BASE = {
    "errors",
    "arrays",
    "data_dir",
    "rng",
    "provenance",
    "results",
    "interrupts",
    "threads",
    "file_writes",
    "path_kinds",
    "mitsuba_import",
    "number_lists",
}
ORDER = ["spectra", "scenes", "render", "gt_export", "learn", "decompose"]
#: The top layer, left to right: a study may run the pipeline, a benchmark a study, the CLI all.
TOP = ["pipeline", "studies", "bench", "cli"]


def _layer(sub: str) -> int:
    """Rank of the ``spectrinsic.<sub>`` layer: base 0, the data-flow packages 1.., the top after."""
    if sub in CORE_BASE:
        return 0
    if sub in ORDER:
        return 1 + ORDER.index(sub)
    assert sub in TOP, f"spectrinsic.{sub} is in no layer: add it to tests/test_packaging.py"
    return 1 + len(ORDER) + TOP.index(sub)


def _pyproject(repo_root: Path) -> dict:
    return tomllib.loads((repo_root / "pyproject.toml").read_text())


def _package_of(folder: Path) -> str:
    return ".".join(folder.relative_to(PACKAGE_DIR.parent).parts)


def test_every_folder_of_modules_is_a_listed_package(repo_root):
    """A folder of modules without ``__init__.py`` would be left out of the wheel."""
    from setuptools import find_packages

    folders = {p.parent for p in PACKAGE_DIR.rglob("*.py") if "__pycache__" not in p.parts}
    assert [f for f in folders if not (f / "__init__.py").is_file()] == []
    find = _pyproject(repo_root)["tool"]["setuptools"]["packages"]["find"]
    found = set(find_packages(str(repo_root), include=find["include"]))
    assert found == {_package_of(f) for f in folders}
    assert "spectrinsic.render.band_path" in found


def test_every_data_folder_is_package_data(repo_root):
    package_data = _pyproject(repo_root)["tool"]["setuptools"]["package-data"]
    for path in PACKAGE_DIR.rglob("*"):
        if not path.is_file() or path.suffix in {".py", ".pyc"} or "__pycache__" in path.parts:
            continue
        package = path.parent
        while not (package / "__init__.py").is_file():
            package = package.parent
        rel = path.relative_to(package).as_posix()
        patterns = package_data.get(_package_of(package), [])
        assert any(Path(rel).match(p) for p in patterns), f"{path} is not package data"


def _module(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """Every module *path* imports, relative imports resolved."""
    tree = ast.parse(path.read_text(), filename=str(path))
    module = _module(path)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level:
            parts = package.split(".")
            anchor = parts[: len(parts) - node.level + 1]
            base = ".".join([*anchor, node.module] if node.module else anchor)
            names.add(base)
            if base == "spectrinsic":  # from .. import errors: the modules themselves
                names.update(f"spectrinsic.{a.name}" for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
    return names


#: The module outside spectrinsic.render that imports Mitsuba: the set-up step, a base module
#: below the renderer and the XML scene reader, which both import Mitsuba through it.
MITSUBA_READERS = frozenset({Path("mitsuba_import.py")})


def _files():
    """``(part, path)``: the package's part a file is in (its subpackage, or ``core``)."""
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        rel = path.relative_to(PACKAGE_DIR)
        yield ("core" if len(rel.parts) == 1 else rel.parts[0]), path


def _own_layer(folder: str, path: Path) -> str:
    """The ``spectrinsic.<sub>`` a file belongs to: its folder, or for core its module."""
    return folder if folder != "core" else path.stem


def test_the_import_reader_resolves_relative_imports():
    sub = PACKAGE_DIR / "render" / "base" / "variants.py"
    names = _imports(sub)
    assert "spectrinsic.errors" in names, names


@pytest.mark.parametrize("folder, path", list(_files()), ids=lambda x: getattr(x, "name", x))
def test_imports_flow_one_way(folder, path):
    own = _own_layer(folder, path)
    for name in _imports(path):
        top = name.split(".")[0]
        if top != "spectrinsic" or name == "spectrinsic":
            continue
        if own in {"__init__", "__main__"}:
            continue  # the root package's own entry points
        sub = name.split(".")[1]
        assert _layer(sub) <= _layer(own), f"{path}: {own} must not import {name}"
    # Besides the renderer, only the set-up step imports Mitsuba: the reader of Mitsuba XML
    # files (issue 41) parses them with Mitsuba's own parser, through that step.
    if folder != "render" and path.relative_to(PACKAGE_DIR) not in MITSUBA_READERS:
        assert not {"mitsuba", "drjit"} & {n.split(".")[0] for n in _imports(path)}, (
            f"{path}: only spectrinsic.render may import mitsuba/drjit"
        )
    if folder != "gt_export" and folder != "decompose":
        assert "OpenEXR" not in {n.split(".")[0] for n in _imports(path)}, (
            f"{path}: only gt_export reads/writes EXR"
        )
