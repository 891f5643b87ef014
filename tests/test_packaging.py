"""Packaging and layering guards: nothing silently left out of the wheel, no wrong-way imports."""

from __future__ import annotations

import ast
import tomllib
from pathlib import Path

import pytest

FOLDERS = {
    "core": "spectrinsic",
    "spectra": "spectrinsic.spectra",
    "scenes": "spectrinsic.scenes",
    "render": "spectrinsic.render",
    "gt_export": "spectrinsic.gt_export",
    "decompose": "spectrinsic.decompose",
    "pipeline": "spectrinsic.pipeline",
    "studies": "spectrinsic.studies",
    "bench": "spectrinsic.bench",
    "cli": "spectrinsic.cli",
}
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
}
ORDER = ["spectra", "scenes", "render", "gt_export", "decompose"]
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


def test_every_package_folder_is_listed(repo_root):
    tool = _pyproject(repo_root)["tool"]["setuptools"]
    listed = set(tool["packages"])
    found = set()
    for folder, package in FOLDERS.items():
        for init in (repo_root / folder).rglob("__init__.py"):
            rel = init.parent.relative_to(repo_root / folder)
            found.add(".".join([package, *rel.parts]) if rel.parts else package)
    assert found == listed
    assert tool["package-dir"] == {v: k for k, v in FOLDERS.items()}


def test_every_data_folder_is_package_data(repo_root):
    package_data = _pyproject(repo_root)["tool"]["setuptools"]["package-data"]
    for folder, package in FOLDERS.items():
        for path in (repo_root / folder).rglob("*"):
            if (
                path.is_file()
                and path.suffix not in {".py", ".pyc"}
                and "__pycache__" not in path.parts
            ):
                rel = path.relative_to(repo_root / folder).as_posix()
                patterns = package_data.get(package, [])
                assert any(Path(rel).match(p) for p in patterns), (
                    f"{folder}/{rel} is not package data"
                )


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


def _files():
    root = Path(__file__).resolve().parents[1]
    for folder in FOLDERS:
        for path in sorted((root / folder).rglob("*.py")):
            yield folder, path


def _own_layer(folder: str, path: Path) -> str:
    """The ``spectrinsic.<sub>`` a file belongs to: its folder, or for core its module/subpackage."""
    if folder != "core":
        return folder
    rel = path.relative_to(Path(__file__).resolve().parents[1] / "core")
    return rel.parts[0].removesuffix(".py") if len(rel.parts) > 0 else ""


@pytest.mark.parametrize("folder, path", list(_files()), ids=lambda x: getattr(x, "name", x))
def test_imports_flow_one_way(folder, path):
    bare = {
        "spectra",
        "scenes",
        "render",
        "gt_export",
        "decompose",
        "core",
        "pipeline",
        "studies",
        "bench",
        "cli",
    }
    own = _own_layer(folder, path)
    for name in _imports(path):
        top = name.split(".")[0]
        assert top not in bare, f"{path}: bare import {name!r}; use spectrinsic.{name}"
        if top != "spectrinsic" or name == "spectrinsic":
            continue
        if own in {"__init__", "__main__"}:
            continue  # the root package's own entry points
        sub = name.split(".")[1]
        assert _layer(sub) <= _layer(own), f"{path}: {own} must not import {name}"
    if folder != "render":
        assert not {"mitsuba", "drjit"} & {n.split(".")[0] for n in _imports(path)}, (
            f"{path}: only spectrinsic.render may import mitsuba/drjit"
        )
    if folder != "gt_export" and folder != "decompose":
        assert "OpenEXR" not in {n.split(".")[0] for n in _imports(path)}, (
            f"{path}: only gt_export reads/writes EXR"
        )
