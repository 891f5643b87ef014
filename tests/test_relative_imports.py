"""Inside the package every import of the package is explicit-relative (``from ..spectra import
registry``), so the checkout maps each import to a folder without the installed package; tests,
scripts and docs keep the absolute ``spectrinsic.`` form (issue 35)."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def absolute_imports(source: str) -> list[int]:
    """Line numbers of the imports of ``spectrinsic`` written absolute, function-level ones and
    ``if TYPE_CHECKING:`` ones included."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and node.level == 0:
            names = [node.module or ""]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        if any(n.split(".")[0] == "spectrinsic" for n in names):
            lines.append(node.lineno)
    return lines


def test_the_scanner_finds_absolute_imports_of_the_package():
    code = (
        "import numpy\n"
        "from spectrinsic.errors import X\n"
        "from . import y\n"
        "def f():\n"
        "    import spectrinsic.render as r\n"
        "from spectrinsic_other import z\n"
    )
    assert absolute_imports(code) == [2, 5]


def test_no_module_of_the_package_imports_it_absolutely():
    offenders = [
        f"{path.relative_to(ROOT)}:{line}"
        for path in sorted((ROOT / "spectrinsic").rglob("*.py"))
        for line in absolute_imports(path.read_text(encoding="utf-8"))
    ]
    assert len(list((ROOT / "spectrinsic").rglob("*.py"))) > 100  # the scan sees the package
    assert offenders == [], "write these as relative imports (from ..spectra import ...):\n" + (
        "\n".join(offenders)
    )
