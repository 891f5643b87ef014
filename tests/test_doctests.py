"""Every ``>>>`` example in the installed package runs and gives what it shows.

Modules are found with :func:`pkgutil.walk_packages` over the installed ``spectrinsic`` and
imported by name, never by path (ARCHITECTURE.md: doctests run by module name).
"""

from __future__ import annotations

import doctest
import importlib
import importlib.util
import pkgutil
from pathlib import Path

import colour  # noqa: F401  (its import sets numpy's legacy printing: done before any example)
import numpy as np
import pytest

import spectrinsic


def _modules_with_examples() -> list[str]:
    """Names of the package's modules whose source holds a ``>>>`` example."""
    names = []
    for info in pkgutil.walk_packages(spectrinsic.__path__, prefix="spectrinsic."):
        spec = importlib.util.find_spec(info.name)
        if spec is None or not spec.origin or not spec.origin.endswith(".py"):
            continue
        if ">>>" in Path(spec.origin).read_text(encoding="utf-8"):
            names.append(info.name)
    return sorted(names)


MODULES = _modules_with_examples()


def test_every_source_file_with_examples_is_found(repo_root: Path):
    """The discovery by module name misses no file of the source tree that has examples."""
    files = [
        p
        for p in (repo_root / "spectrinsic").rglob("*.py")
        if ">>>" in p.read_text(encoding="utf-8")
    ]
    assert len(MODULES) == len(files) >= 11


@pytest.mark.parametrize("name", MODULES)
def test_examples(name: str):
    module = importlib.import_module(name)
    # colour-science's import calls np.set_printoptions(legacy="1.13") for the whole process, so
    # an array's repr depends on whether it was imported; examples are judged as numpy prints
    # by default (those of spectrinsic print lists, which read the same either way)
    with np.printoptions(legacy=False):
        result = doctest.testmod(
            module,
            optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
            report=True,
            verbose=False,
        )
    assert result.attempted > 0, f"{name}: no example ran"
    assert result.failed == 0, (
        f"{name}: {result.failed} of {result.attempted} examples failed (see above)"
    )
