"""House rules checked on the source tree: short, simple functions (STYLE.md)."""

from __future__ import annotations

import ast
import warnings
from pathlib import Path

#: The longest function body allowed, in source lines, not counting its docstring.
MAX_BODY_LINES = 60
#: Past this many lines a module of the package draws a warning, not a failure (issue 35: the
#: rule measures concepts, not lines): it is split by concept when it holds more than one, or it
#: says in a ``# long module: <reason>`` line why it is one concept; that line silences the warning.
MAX_MODULE_LINES = 450
#: Past this a module fails whatever its reason (STYLE.md: no god modules).
HARD_MODULE_LINES = 900
#: The comment that states why a module past :data:`MAX_MODULE_LINES` is one concept.
LONG_MODULE_REASON = "# long module:"
#: The folder that is the installed package.
PACKAGE_FOLDERS = ("spectrinsic",)


def _body_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """Source lines spanned by a function's body, its docstring left out (0 for a bare docstring)."""
    body = node.body
    first = body[0]
    if (
        isinstance(first, ast.Expr)
        and isinstance(first.value, ast.Constant)
        and isinstance(first.value.value, str)
    ):
        body = body[1:]
    if not body:
        return 0
    end = max(getattr(n, "end_lineno", n.lineno) or n.lineno for n in body)
    return end - body[0].lineno + 1


def long_functions(source: str, filename: str = "<string>") -> list[tuple[str, int, int]]:
    """Every function in ``source`` whose body exceeds :data:`MAX_BODY_LINES`.

    Returns ``(qualified name, line number, body lines)`` tuples; methods and nested functions
    are named ``Outer.inner``.
    """
    found: list[tuple[str, int, int]] = []

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                name = f"{prefix}{child.name}"
                if not isinstance(child, ast.ClassDef):
                    lines = _body_lines(child)
                    if lines > MAX_BODY_LINES:
                        found.append((name, child.lineno, lines))
                visit(child, name + ".")
            else:
                visit(child, prefix)

    visit(ast.parse(source, filename=filename), "")
    return found


def test_the_checker_counts_body_lines_without_the_docstring():
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_BODY_LINES))
    ok = f'def f():\n    """Doc\n    string."""\n{body}\n'
    assert long_functions(ok) == []
    too_long = ok + "    return x0\n"
    assert long_functions(too_long) == [("f", 1, MAX_BODY_LINES + 1)]
    nested = "class A:\n    def g(self):\n" + "\n".join(
        f"        y{i} = {i}" for i in range(MAX_BODY_LINES + 5)
    )
    assert long_functions(nested) == [("A.g", 2, MAX_BODY_LINES + 5)]


def test_no_function_body_is_over_sixty_lines(repo_root: Path):
    offenders = []
    for folder in PACKAGE_FOLDERS:
        for path in sorted((repo_root / folder).rglob("*.py")):
            rel = path.relative_to(repo_root)
            for name, line, lines in long_functions(path.read_text(), str(rel)):
                offenders.append(f"{rel}:{line} {name} ({lines} lines)")
    assert not offenders, (
        f"functions with more than {MAX_BODY_LINES} body lines; split them into named steps:\n"
        + "\n".join(offenders)
    )


def long_modules(root: Path, limit: int = MAX_MODULE_LINES) -> list[str]:
    """``"<path> (<n> lines)"`` for every module under the package folders of *root* that holds
    more than *limit* lines and does not say why (a ``# long module: <reason>`` line) when
    *limit* is :data:`MAX_MODULE_LINES`."""
    found = []
    for folder in PACKAGE_FOLDERS:
        for path in sorted((root / folder).rglob("*.py")):
            text = path.read_text(encoding="utf-8")
            n = len(text.splitlines())
            reason = limit == MAX_MODULE_LINES and any(
                line.strip().startswith(LONG_MODULE_REASON) and line.split(":", 1)[1].strip()
                for line in text.splitlines()
            )
            if n > limit and not reason:
                found.append(f"{path.relative_to(root)} ({n} lines)")
    return found


def test_the_module_checker_counts_lines_in_every_package_folder(tmp_path: Path):
    (tmp_path / "spectrinsic" / "scenes" / "sub").mkdir(parents=True)
    (tmp_path / "spectrinsic" / "ok.py").write_text("x = 1\n" * MAX_MODULE_LINES)
    big = tmp_path / "spectrinsic" / "scenes" / "sub" / "big.py"
    big.write_text("x = 1\n" * (MAX_MODULE_LINES + 1))
    said = tmp_path / "spectrinsic" / "said.py"
    said.write_text("# long module: one table\n" + "x = 1\n" * MAX_MODULE_LINES)
    empty = tmp_path / "spectrinsic" / "empty_reason.py"
    empty.write_text("# long module:\n" + "x = 1\n" * MAX_MODULE_LINES)
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "big_test.py").write_text("x = 1\n" * 1000)  # not the package
    assert long_modules(tmp_path) == [
        f"spectrinsic/empty_reason.py ({MAX_MODULE_LINES + 1} lines)",
        f"spectrinsic/scenes/sub/big.py ({MAX_MODULE_LINES + 1} lines)",
    ]
    assert long_modules(tmp_path, HARD_MODULE_LINES) == []
    said.write_text("# long module: one table\n" + "x = 1\n" * HARD_MODULE_LINES)
    assert long_modules(tmp_path, HARD_MODULE_LINES) == [
        f"spectrinsic/said.py ({HARD_MODULE_LINES + 1} lines)"
    ]


def test_long_modules_say_why_or_draw_a_warning(repo_root: Path):
    """Past 450 lines: a warning (shown in pytest's summary), not a failure."""
    offenders = long_modules(repo_root)
    if offenders:
        warnings.warn(
            f"modules past {MAX_MODULE_LINES} lines that do not say why: split each by concept "
            f"if it holds more than one, else add a '{LONG_MODULE_REASON} <reason>' line:\n"
            + "\n".join(offenders),
            stacklevel=1,
        )


def test_no_module_is_over_900_lines(repo_root: Path):
    offenders = long_modules(repo_root, HARD_MODULE_LINES)
    assert not offenders, (
        f"modules with more than {HARD_MODULE_LINES} lines; split them into modules named for "
        "what they hold:\n" + "\n".join(offenders)
    )


def test_complexity_and_statement_limits_hold(repo_root):
    """ruff's C901 (McCabe complexity) and PLR0915 (statements per function), with the limits of
    pyproject.toml, run here too, so the rule holds wherever ``make test`` runs (CI included)."""
    import subprocess
    import sys

    ruff = Path(sys.executable).with_name("ruff")
    result = subprocess.run(
        [str(ruff), "check", "--select", "C901,PLR0915", "--no-cache", *PACKAGE_FOLDERS],
        cwd=repo_root,
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr
