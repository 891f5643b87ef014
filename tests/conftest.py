"""Shared fixtures: the spectral data directory, the repository root, and tiny scenes built
directly from scene-model records for the render and ground-truth tests."""

from __future__ import annotations

import importlib.abc
import os
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene

REPO_ROOT = Path(__file__).resolve().parents[1]

#: What marks a test module's tests ``render`` (they run Mitsuba): naming Mitsuba, Dr.Jit or a
#: function that renders, or a command that renders; ``make test-unit`` runs the others.
_RENDERS = re.compile(
    r"\b(?:mitsuba|drjit|render_\w+|count_passes|run_batches|build_dataset|run_study|"
    r"relight_sample|bench_\w+)\b|\"(?:dataset|render|relight|study|bench)\""
)
#: The scene fixtures of the render tests: a test taking one is marked ``render`` too.
_RENDER_FIXTURES = frozenset({"make_plane", "make_room", "make_corner"})
#: ``make test-unit`` sets it: Dr.Jit (which every Mitsuba render needs) cannot be imported in
#: this process then, so a test that renders but was not marked fails loudly instead of slowing
#: the tier down (finding Mitsuba's shipped data files, without importing it, stays allowed).
UNIT_ENV = "SPECTRINSIC_UNIT_TESTS"


class _NoMitsuba(importlib.abc.MetaPathFinder):
    """Refuses to import Dr.Jit, and so to render (the unit tier renders nothing)."""

    def find_spec(self, name, path=None, target=None):  # noqa: ANN001, ANN201
        if name.split(".")[0] == "drjit":
            raise ImportError(
                f"{name} imported in the unit tier ({UNIT_ENV}=1): the test renders, so mark it "
                "'render' (tests/conftest.py _RENDERS) or run it with make test"
            )
        return None


def pytest_configure(config: pytest.Config) -> None:
    if os.environ.get(UNIT_ENV) == "1":
        sys.meta_path.insert(0, _NoMitsuba())


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark ``render`` every test of a module that renders (:data:`_RENDERS`) and every test
    taking a render scene fixture; ``-m "not render"`` (``make test-unit``) leaves them out."""
    renders: dict[Path, bool] = {}
    for item in items:
        path = Path(item.path)
        if path not in renders:
            renders[path] = bool(_RENDERS.search(path.read_text(encoding="utf-8")))
        if renders[path] or _RENDER_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.render)


def _data_dir() -> Path | None:
    env = os.environ.get("SPECTRINSIC_DATA", "").strip()
    candidates = [Path(env)] if env else []
    candidates.append(REPO_ROOT.parent / "shared" / "data")
    for c in candidates:
        if (c / "sfu_barnard2002").is_dir():
            return c.resolve()
    return None


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return REPO_ROOT


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The spectral data directory (../shared/data in CI); tests needing it skip with a reason."""
    path = _data_dir()
    if path is None:
        pytest.skip("no spectral data directory: set SPECTRINSIC_DATA or place ../shared/data")
    return path


@pytest.fixture(scope="session")
def torch():
    """PyTorch for the adapter tests. ``make test-torch`` (run by CI) installs it and sets
    ``SPECTRINSIC_REQUIRE_TORCH=1``, so there a missing torch fails instead of skipping."""
    if os.environ.get("SPECTRINSIC_REQUIRE_TORCH") == "1":
        import torch

        return torch
    return pytest.importorskip(
        "torch", reason="PyTorch is an optional extra: make test-torch installs it"
    )


#: A small valid scene file (FORMAT.md's example reduced to a grey quad, one point light, a
#: 16x16 camera), as YAML text: the input of the CLI's refusal and output-folder tests.
QUAD_YAML = """\
name: quad
materials: {grey: "flat:0.5"}
meshes:
  - name: ground
    vertices: [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]
    faces: [[0, 1, 2], [0, 2, 3]]
    material: grey
lights:
  - {kind: point, spectrum: "cie:D65", power: 4, position: [0, 0, 2]}
camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 16, height: 16}
"""
#: The command-line options of the tiny dataset builds: the preview preset at 16 x 16 pixels,
#: 2 samples per pixel.
TINY_BUILD = ["--preset", "preview", "--resolution", "16x16", "--spp", "2"]


def one_line_error(capsys: pytest.CaptureFixture[str], *needles: str) -> str:
    """The error a command just printed: one line on stderr, no traceback, holding every one of
    *needles* (the house rule for bad input)."""
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "Traceback" not in err, err
    for needle in needles:
        assert needle in err, err
    return err


#: The text of a user's own file, which no command may replace or delete.
USER_TEXT = "the user's own file\n"


@pytest.fixture
def outside(tmp_path: Path) -> Path:
    """A user's file (:data:`USER_TEXT`) outside any output folder."""
    path = tmp_path / "elsewhere" / "precious.txt"
    path.parent.mkdir()
    path.write_text(USER_TEXT)
    return path


def quad(
    corner: Sequence[float], u: Sequence[float], v: Sequence[float]
) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (4, 3) and faces (2, 3) of the parallelogram corner + [0,1]u + [0,1]v."""
    c, a, b = (np.asarray(x, float) for x in (corner, u, v))
    return np.stack([c, c + a, c + a + b, c + b]), np.array([[0, 1, 2], [0, 2, 3]])


def plane_scene(
    reflectance: str,
    light_spectrum: str,
    *,
    tilt_deg: float = 0.0,
    size: int = 16,
    power: float = 1.0,
) -> Scene:
    """A large horizontal plane seen straight from above, lit by a directional light.

    The light arrives *tilt_deg* from the normal; the camera sees only the plane.
    """
    vertices, faces = quad((-50, -50, 0), (100, 0, 0), (0, 100, 0))
    t = np.radians(tilt_deg)
    return Scene(
        name="plane",
        meshes=(Mesh("plane", vertices, faces, np.zeros(2, np.int64), object_id=0),),
        materials=(Material("plane", reflectance),),
        lights=(
            Light("directional", light_spectrum, power, direction=(np.sin(t), 0.0, -np.cos(t))),
        ),
        camera=Camera(
            origin=(0, 0, 2), target=(0, 0, 0), up=(0, 1, 0), fov_deg=30, width=size, height=size
        ),
    )


def corner_scene(
    first: Material,
    wall: str = "munsell:5R 5/12",
    *,
    size: int = 16,
    light: str = "cie:D65",
    power: float = 5.0,
    wall_half: float = 3.0,
) -> Scene:
    """A wall of material *first* (plane x = 0, facing +x) beside a coloured *wall* (plane
    y = 1, facing -y, x ∈ [0, 2 *wall_half*], |z| ≤ *wall_half*). A distant light (*light* at
    *power*) along +y lights the coloured wall head-on and grazes the first one (cos θ = 0),
    which so receives only light bounced off the coloured wall. The camera sees the first wall
    alone."""
    first_v, first_f = quad((0, -3, -3), (0, 0, 6), (0, 4, 0))  # seen from its back: two-sided
    h = wall_half
    wall_v, wall_f = quad((0, 1, -h), (2 * h, 0, 0), (0, 0, 2 * h))
    return Scene(
        name="corner",
        meshes=(
            Mesh(first.name, first_v, first_f, np.zeros(2, np.int64), object_id=0),
            Mesh("wall", wall_v, wall_f, np.ones(2, np.int64), object_id=1),
        ),
        materials=(first, Material("wall", wall)),
        lights=(Light("directional", light, power, direction=(0.0, 1.0, 0.0)),),
        camera=Camera(
            origin=(1.0, -0.5, 0.0),
            target=(0.0, 0.2, 0.0),
            up=(0, 0, 1),
            fov_deg=20,
            width=size,
            height=size,
        ),
    )


def _box(lo: Sequence[float], hi: Sequence[float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Axis-aligned box: vertices, faces and a face -> side index (0..5: -x,+x,-y,+y,-z,+z)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    sides = [
        quad((x0, y0, z0), (0, 0, z1 - z0), (0, y1 - y0, 0)),
        quad((x1, y0, z0), (0, y1 - y0, 0), (0, 0, z1 - z0)),
        quad((x0, y0, z0), (x1 - x0, 0, 0), (0, 0, z1 - z0)),
        quad((x0, y1, z0), (0, 0, z1 - z0), (x1 - x0, 0, 0)),
        quad((x0, y0, z0), (0, y1 - y0, 0), (x1 - x0, 0, 0)),
        quad((x0, y0, z1), (x1 - x0, 0, 0), (0, y1 - y0, 0)),
    ]
    vertices = np.concatenate([s[0] for s in sides])
    faces = np.concatenate([s[1] + 4 * i for i, s in enumerate(sides)])
    return vertices, faces, np.repeat(np.arange(6), 2)


def box_room(
    wall_spectra: Sequence[str] = (
        "munsell:5R 5/12",
        "munsell:5G 6/8",
        "munsell:5B 5/8",
        "munsell:5Y 8/10",
        "munsell:5Y 8/2",
        "munsell:5Y 8/2",
    ),
    cube_spectrum: str = "munsell:5P 5/10",
    lights: Sequence[tuple[str, str, float]] = (
        ("point", "planck:2800K", 1.5),
        ("area", "daylight:6500K", 3.0),
    ),
    size: int = 24,
) -> Scene:
    """A closed 2 m room with coloured walls (interreflections), a cube, and its lights.

    ``lights`` are ``(kind, spectrum, power)``: a point light near the ceiling and a downward
    area light under it.
    """
    room_v, room_f, room_side = _box((-1, -1, 0), (1, 1, 2))
    cube_v, cube_f, _ = _box((-0.3, -0.2, 0), (0.3, 0.4, 0.6))
    materials = tuple(Material(f"wall{i}", s) for i, s in enumerate(wall_spectra)) + (
        Material("cube", cube_spectrum),
    )
    placed = []
    for i, (kind, spectrum, power) in enumerate(lights):
        if kind == "area":
            placed.append(
                Light(
                    "area",
                    spectrum,
                    power,
                    position=(0.3, -0.3, 1.95),
                    direction=(0, 0, -1),
                    size=(0.5, 0.5),
                    name=f"light{i}",
                )
            )
        else:
            placed.append(
                Light(
                    kind,
                    spectrum,
                    power,
                    position=(-0.5, 0.5, 1.6),
                    direction=(0, 0, -1),
                    name=f"light{i}",
                )
            )
    return Scene(
        name="box-room",
        meshes=(
            Mesh("room", room_v, room_f, room_side, object_id=0),
            Mesh("cube", cube_v, cube_f, np.full(len(cube_f), 6, np.int64), object_id=1),
        ),
        materials=materials,
        lights=tuple(placed),
        camera=Camera(
            origin=(0.0, -0.95, 1.2),
            target=(0.1, 0.5, 0.6),
            up=(0, 0, 1),
            fov_deg=75,
            width=size,
            height=size,
        ),
    )


@pytest.fixture(scope="session")
def make_plane() -> Callable[..., Scene]:
    return plane_scene


@pytest.fixture(scope="session")
def make_room() -> Callable[..., Scene]:
    return box_room


@pytest.fixture(scope="session")
def make_corner() -> Callable[..., Scene]:
    return corner_scene
