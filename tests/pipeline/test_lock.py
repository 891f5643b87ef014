"""The dependency lock: constraints.txt pins every declared dependency, make installs with it, and
this environment is the one it describes."""

from __future__ import annotations

import re
import tomllib
from importlib.metadata import PackageNotFoundError, version

import pytest

#: Extras `make setup` installs (the Makefile's pip line).
MAKE_EXTRAS = ("dev", "blender", "distributed")


def _name(requirement: str) -> str:
    return re.split(r"[\s<>=!~\[;]", requirement.strip(), maxsplit=1)[0].lower().replace("_", "-")


def _pins(repo_root) -> dict[str, str]:
    pins = {}
    for line in (repo_root / "constraints.txt").read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            name, sep, pinned = line.partition("==")
            assert sep, f"constraints.txt: {line!r} is not an exact pin (name==version)"
            pins[_name(name)] = pinned.strip()
    return pins


def _declared(repo_root) -> set[str]:
    project = tomllib.loads((repo_root / "pyproject.toml").read_text())["project"]
    reqs = list(project["dependencies"])
    for extra in MAKE_EXTRAS:
        reqs += project["optional-dependencies"][extra]
    return {_name(r) for r in reqs}


def test_every_declared_dependency_is_pinned(repo_root):
    missing = _declared(repo_root) - set(_pins(repo_root))
    assert not missing, f"constraints.txt lacks pins for {sorted(missing)}"


def test_make_installs_with_the_lock(repo_root):
    makefile = (repo_root / "Makefile").read_text()
    assert re.search(r"pip install .*-c constraints\.txt .*\[dev,blender,distributed\]", makefile)
    assert re.search(r"^\$\(DEPS\):.*constraints\.txt", makefile, re.M)  # editing it reinstalls


def test_this_environment_matches_the_lock(repo_root):
    pins = _pins(repo_root)
    for name in sorted(_declared(repo_root)):
        try:
            installed = version(name)
        except PackageNotFoundError:
            pytest.fail(f"{name} is declared but not installed; run make setup")
        assert installed == pins[name], (
            f"{name} {installed} installed, constraints.txt pins {pins[name]}"
        )
