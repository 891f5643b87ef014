"""Floors inside the wings: the sibling folders and modules of a package import one way.

A *sibling* of a package is one entry directly inside it: a subfolder (``render/algebra/``) or a
module at its root (``render/result.py``). :data:`SIBLING_FLOORS` lists, for every package with
subfolders, its siblings floor by floor, lowest first. An import from a module under sibling A
to one under sibling B of the same package (imports inside functions count; ``if
TYPE_CHECKING:`` blocks do not) is an *arrow* A → B. The rule:

* an arrow never goes up: B's floor is at most A's;
* arrows between siblings make no circle, on one floor or across floors;
* every sibling has a floor (a new folder or module is placed here when it is added).

The package's own ``__init__.py`` is its face, above every sibling, and may import any of them.
The import graph is :func:`tests.test_imports.import_graph`'s.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator

import pytest

from tests.test_imports import PACKAGE_DIR, cycles, import_graph

#: The package's import graph, built once for every test here.
_graph = functools.cache(import_graph)


def _root_modules(package: str) -> frozenset[str]:
    """The modules at the root of ``spectrinsic/<package>/``, ``__init__`` left out."""
    return frozenset(p.stem for p in (PACKAGE_DIR / package).glob("*.py")) - {"__init__"}


#: package -> its siblings, floor by floor (lowest first). docs/ARCHITECTURE.md quotes it.
SIBLING_FLOORS: dict[str, tuple[frozenset[str], ...]] = {
    "spectrinsic.render": (
        frozenset({"settings", "result"}),  # the records in and out (no Mitsuba)
        frozenset({"algebra"}),  # numpy only
        frozenset({"base"}),  # the Mitsuba base under both wings
        frozenset({"band_path", "passes"}),  # the two wings, independent of each other
        frozenset({"budget", "spectral", "probe"}),
        frozenset({"scene_render", "batches", "transport_render"}),  # the drivers
    ),
    "spectrinsic.gt_export": (
        frozenset({"formats"}),  # EXR, PNG, file-name slugs
        frozenset({"layers"}),  # the ground-truth layers
        frozenset({"sample"}),  # one sample folder
        frozenset({"folders"}),  # output folders: the --out rule, staging, the dataset marker
        frozenset({"dataset", "relight"}),  # a built dataset's products; relighting
    ),
    "spectrinsic.decompose": (
        frozenset({"_validation"}),
        frozenset({"decomposition"}),  # the record and protocol
        frozenset({"metrics"}),
        frozenset({"methods", "synthetic"}),
        frozenset({"evaluation"}),
        frozenset({"report"}),  # reads evaluation's record; called by the CLI
    ),
    "spectrinsic.scenes": (
        _root_modules("scenes") - {"sources"},  # records, geometry, library, file readers
        frozenset({"generators"}),
        frozenset({"sources"}),  # where a sample's scene comes from: a generator or a file
    ),
    "spectrinsic.studies": (
        _root_modules("studies") - {"registry"},
        frozenset({"photometric", "reconstruction", "rendering", "sim2real"}),
        frozenset({"registry"}),  # the list of studies
    ),
}


def sibling_of(package: str, module: str) -> str | None:
    """The sibling of *package* that holds *module* (``None``: outside it, or its face)."""
    prefix = package + "."
    return module[len(prefix) :].split(".")[0] if module.startswith(prefix) else None


def sibling_arrows(package: str, graph: dict[str, set[str]]) -> Iterator[tuple[str, str, str, str]]:
    """``(sibling A, sibling B, module, imported module)`` of every arrow between two siblings."""
    for module, deps in sorted(graph.items()):
        a = sibling_of(package, module)
        for dep in sorted(deps):
            b = sibling_of(package, dep)
            if a is not None and b is not None and a != b:
                yield a, b, module, dep


def floor_of(floors: tuple[frozenset[str], ...]) -> dict[str, int]:
    return {name: i for i, names in enumerate(floors) for name in names}


def upward_arrows(
    package: str, floors: tuple[frozenset[str], ...], graph: dict[str, set[str]]
) -> list[str]:
    """``"module -> imported"`` of every arrow from a lower sibling to a higher one."""
    floor = floor_of(floors)
    return [
        f"{m} -> {d} ({a}: floor {floor[a]}, {b}: floor {floor[b]})"
        for a, b, m, d in sibling_arrows(package, graph)
        if a in floor and b in floor and floor[b] > floor[a]
    ]


def sibling_cycles(package: str, graph: dict[str, set[str]]) -> list[frozenset[str]]:
    """Circles of arrows between the siblings of *package*."""
    folded: dict[str, set[str]] = {}
    for a, b, _, _ in sibling_arrows(package, graph):
        folded.setdefault(a, set()).add(b)
        folded.setdefault(b, set())
    return cycles(folded)


def siblings(package: str) -> set[str]:
    """Every subfolder (with an ``__init__.py``) and module at the root of *package*."""
    folder = PACKAGE_DIR.parent.joinpath(*package.split("."))
    return {p.stem for p in folder.glob("*.py") if p.name != "__init__.py"} | {
        p.name for p in folder.iterdir() if (p / "__init__.py").is_file()
    }


def test_the_checker_finds_an_upward_arrow_and_a_circle():
    """A lower sibling importing a higher one, and two siblings on a floor importing each other,
    are found; an arrow down and a module importing its own folder are not."""
    floors = (frozenset({"low"}), frozenset({"mid_a", "mid_b"}), frozenset({"top"}))
    graph = {
        "p.low.x": {"p.top"},  # up
        "p.mid_a.y": {"p.low.x", "p.mid_b"},  # down, across the floor
        "p.mid_b": {"p.mid_a.y"},  # back across: a circle
        "p.top": {"p.top.z"},
        "p.top.z": set(),
        "p": {"p.top"},  # the face
    }
    assert upward_arrows("p", floors, graph) == ["p.low.x -> p.top (low: floor 0, top: floor 2)"]
    assert sibling_cycles("p", graph) == [frozenset({"mid_a", "mid_b"})]
    del graph["p.mid_b"]
    assert sibling_cycles("p", graph) == []


@pytest.mark.parametrize("package", sorted(SIBLING_FLOORS))
def test_every_sibling_has_one_floor(package):
    floors = SIBLING_FLOORS[package]
    listed = [name for names in floors for name in names]
    assert len(listed) == len(set(listed)), f"{package}: a sibling on two floors"
    assert set(listed) == siblings(package), (
        f"{package}: place these siblings on a floor of SIBLING_FLOORS: "
        f"{sorted(siblings(package) - set(listed))}; stale: {sorted(set(listed) - siblings(package))}"
    )


def test_every_package_with_subfolders_has_floors():
    """A package whose root holds both folders and modules states their order."""
    missing = [
        ".".join(p.relative_to(PACKAGE_DIR.parent).parts)
        for p in sorted(PACKAGE_DIR.iterdir())
        if (p / "__init__.py").is_file() and any((q / "__init__.py").is_file() for q in p.iterdir())
    ]
    assert sorted(set(missing) - set(SIBLING_FLOORS)) == []


@pytest.mark.parametrize("package", sorted(SIBLING_FLOORS))
def test_no_upward_arrow_between_siblings(package):
    graph, _ = _graph()
    wrong = upward_arrows(package, SIBLING_FLOORS[package], graph)
    assert not wrong, "upward arrows inside a wing:\n" + "\n".join(wrong)


@pytest.mark.parametrize("package", sorted(SIBLING_FLOORS))
def test_no_circle_between_siblings(package):
    graph, _ = _graph()
    found = sibling_cycles(package, graph)
    assert not found, "circles between siblings: " + "; ".join(map(str, map(sorted, found)))
