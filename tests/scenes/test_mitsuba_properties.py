"""Property-based tests of Mitsuba XML attributes (issue 44): a drawn scene loads or is refused.

Every attribute a user types into a Mitsuba XML file is text: numbers (``inf``, ``nan``,
``1e400``, empty, garbage), ``<point x= y= z=/>`` and ``value="a, b, c"`` forms, ``<rgb
value=>`` with one or three values, transforms (translate, scale, rotate, matrix, lookat),
written-out spectra ``400:0.5, 700:x``, film sizes, BSDF parameters (``alpha``, ``int_ior`` as a
number or a material name), ``$``-parameters with their ``<default>``, an environment map's
``scale`` and a mask's ``opacity``. Each drawn file must give a valid scene (finite lights,
vertices and a whole film) or one :class:`~spectrinsic.errors.SpectrinsicError` line, before
any rendering, and no RuntimeWarning on the way (warnings are errors here). The face budget is
drawn around its limit: the refusal comes exactly when the declared faces pass it.

Same settings as ``tests/test_properties.py`` (derandomized, ``SPECTRINSIC_PROPERTY_EXAMPLES``;
``make test-properties`` runs many more examples).
"""

from __future__ import annotations

import math
import tempfile
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from tests.test_properties import NUMBER_TEXT, SETTINGS, _refused_in_one_line

hypothesis = pytest.importorskip("hypothesis", reason="hypothesis is in the dev extra")
st = pytest.importorskip("hypothesis.strategies")

from spectrinsic.scenes.model import Scene  # noqa: E402
from spectrinsic.scenes.sources import load_scene_file  # noqa: E402

#: Attribute text where parsers break: :data:`NUMBER_TEXT` and a few more shapes of text.
TEXT = st.one_of(
    NUMBER_TEXT,
    st.sampled_from(["-inf", "1e-400", "0x10", "1,2", " 2 ", "1 2 3", "$p", "$missing", "1e20"]),
)
#: Mostly ordinary values (one in ten odd), so that many drawn files get past Mitsuba's parser
#: and reach the reader's own checks.
NUMBER = st.integers(0, 9).flatmap(
    lambda i: TEXT if i == 0 else st.sampled_from(["0.5", "1", "0.8", "0.25"])
)


def _mostly(usual: list[str]) -> st.SearchStrategy[str]:
    """One of *usual*, or odd :data:`TEXT` one time in ten."""
    return st.integers(0, 9).flatmap(lambda i: TEXT if i == 0 else st.sampled_from(usual))


def _point(name: str, tag: str = "point") -> st.SearchStrategy[str]:
    xyz = st.builds(
        lambda x, y, z: f'<{tag} name="{name}" x="{x}" y="{y}" z="{z}"/>', NUMBER, NUMBER, NUMBER
    )
    value = st.builds(lambda v: f'<{tag} name="{name}" value="{v}"/>', st.one_of(TEXT, NUMBER))
    return st.one_of(xyz, value)


def _colour(name: str) -> st.SearchStrategy[str]:
    one = NUMBER.map(lambda v: f'<rgb name="{name}" value="{v}"/>')
    three = st.builds(lambda a, b, c: f'<rgb name="{name}" value="{a}, {b}, {c}"/>', *[NUMBER] * 3)
    spectrum = st.builds(
        lambda a, b: f'<spectrum name="{name}" value="400:{a}, 700:{b}"/>', NUMBER, NUMBER
    )
    plain = NUMBER.map(lambda v: f'<spectrum name="{name}" value="{v}"/>')
    return st.one_of(one, three, spectrum, plain)


def _transform() -> st.SearchStrategy[str]:
    translate = st.builds(lambda x, y: f'<translate x="{x}" y="{y}"/>', NUMBER, NUMBER)
    scale = st.one_of(
        NUMBER.map(lambda v: f'<scale value="{v}"/>'),
        st.builds(lambda x, z: f'<scale x="{x}" z="{z}"/>', NUMBER, NUMBER),
    )
    rotate = st.builds(lambda a, z: f'<rotate z="{z}" angle="{a}"/>', NUMBER, NUMBER)
    size = st.integers(0, 9).flatmap(lambda i: st.integers(0, 17) if i == 0 else st.just(16))
    matrix = size.flatmap(lambda n: st.lists(NUMBER, min_size=n, max_size=n)).map(
        lambda m: f'<matrix value="{" ".join(m)}"/>'
    )
    lookat = st.builds(
        lambda o, t: f'<lookat origin="{o}" target="{t}" up="0, 0, 1"/>',
        _mostly(["0, 0, 3", "1, 1, 1"]),
        _mostly(["0, 0, 0"]),
    )
    steps = st.lists(st.one_of(translate, scale, rotate, matrix, lookat), max_size=3)
    return steps.map(lambda s: f'<transform name="to_world">{"".join(s)}</transform>')


def _bsdf() -> st.SearchStrategy[str]:
    diffuse = _colour("reflectance").map(lambda c: f'<bsdf type="diffuse">{c}</bsdf>')
    rough = st.builds(
        lambda kind, a, d: (
            f'<bsdf type="{kind}"><float name="alpha" value="{a}"/>'
            f'<string name="distribution" value="{d}"/></bsdf>'
        ),
        st.sampled_from(["roughplastic", "roughconductor", "roughdielectric"]),
        NUMBER,
        _mostly(["ggx"]),
    )
    ior = st.one_of(
        NUMBER.map(lambda v: f'<float name="int_ior" value="{v}"/>'),
        st.sampled_from(["water", "bk7", "diamond", "nope", ""]).map(
            lambda v: f'<string name="int_ior" value="{v}"/>'
        ),
    )
    glass = st.builds(lambda i: f'<bsdf type="dielectric">{i}</bsdf>', ior)
    mask = st.builds(
        lambda o, inner: f'<bsdf type="mask"><float name="opacity" value="{o}"/>{inner}</bsdf>',
        NUMBER,
        diffuse,
    )
    return st.one_of(st.just(""), diffuse, rough, glass, mask)


def _emitters() -> st.SearchStrategy[str]:
    point = st.builds(
        lambda p, c: f'<emitter type="point">{p}{c}</emitter>',
        _point("position"),
        _colour("intensity"),
    )
    sky = _colour("radiance").map(lambda c: f'<emitter type="constant">{c}</emitter>')
    sun = st.builds(
        lambda d, c: f'<emitter type="directional">{d}{c}</emitter>',
        _point("direction", "vector"),
        _colour("irradiance"),
    )
    envmap = NUMBER.map(
        lambda s: (
            '<emitter type="envmap"><string name="filename" value="sky.exr"/>'
            f'<float name="scale" value="{s}"/></emitter>'
        )
    )
    return st.lists(st.one_of(point, point, sky, sun, envmap), min_size=1, max_size=2).map("".join)


@st.composite
def _xml_scenes(draw: st.DrawFn) -> str:
    """A scene: a floor (drawn transform and BSDF), maybe a sphere, drawn emitters, a camera
    with a drawn film, and a ``$p`` parameter whose ``<default>`` is drawn too."""
    sphere = draw(st.one_of(st.just(""), _point("center")))
    if sphere:
        radius = draw(NUMBER)
        sphere = f'<shape type="sphere">{sphere}<float name="radius" value="{radius}"/></shape>'
    film = "".join(
        f'<integer name="{side}" value="{draw(_mostly(["8", "6"]))}"/>'
        for side in ("width", "height")
    )
    return (
        f'<scene version="3.0.0"><default name="p" value="{draw(NUMBER)}"/>'
        f'<shape type="rectangle">{draw(_transform())}{draw(_bsdf())}</shape>{sphere}'
        f"{draw(_emitters())}"
        f'<sensor type="perspective"><float name="fov" value="{draw(NUMBER)}"/>'
        '<transform name="to_world"><lookat origin="0, -3, 1" target="0, 0, 0" up="0, 0, 1"/>'
        f'</transform><film type="hdrfilm">{film}</film></sensor></scene>'
    )


def _write_sky(path: Path) -> None:
    from spectrinsic.mitsuba_import import import_mitsuba

    mi = import_mitsuba()
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    mi.Bitmap(np.full((4, 8, 3), 0.5, np.float32)).write(str(path))


def _read(text: str, prepare: Callable[[Path], None] | None = None) -> Scene | str:
    """The scene :func:`load_scene_file` reads from *text*, or its refusal's message after
    asserting that it is one line; a RuntimeWarning on the way fails (it is raised here)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.xml"
        path.write_text(text)
        if prepare is not None:
            prepare(Path(tmp))
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            try:
                return load_scene_file(path)
            except Exception as exc:  # noqa: BLE001 - the property is about which exceptions escape
                _refused_in_one_line(exc)
                return str(exc)


@SETTINGS
@hypothesis.given(text=_xml_scenes())
def test_a_drawn_mitsuba_xml_scene_loads_valid_or_is_refused_in_one_line(text):
    scene = _read(text, lambda folder: _write_sky(folder / "sky.exr"))
    if isinstance(scene, str):
        return
    camera = scene.camera
    assert isinstance(camera.width, int) and isinstance(camera.height, int)
    assert camera.width >= 1 and camera.height >= 1
    assert np.isfinite(np.asarray(camera.origin, float)).all()
    for light in scene.lights:
        assert math.isfinite(light.power) and light.power > 0, light
        for vector in (light.position, light.direction):
            assert vector is None or np.isfinite(np.asarray(vector, float)).all(), light
    for mesh in scene.meshes:
        assert np.isfinite(mesh.vertices).all() and len(mesh.faces) > 0


def _ply_header(faces: int) -> str:
    return (
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        f"property float z\nelement face {faces}\nproperty list uchar int vertex_indices\n"
        "end_header\n"
    )


@SETTINGS
@hypothesis.given(
    spheres=st.integers(0, 4),
    references=st.integers(1, 6),
    share=st.floats(0.8, 1.2),
)
def test_the_xml_face_budget_refuses_exactly_the_scenes_past_it(spheres, references, share):
    """PLY references whose headers declare faces around the budget, plus spheres: the budget
    refusal comes exactly when the declared total passes :data:`MAX_FACES`. Below it the PLY's
    missing body is refused instead (one line too), so no large mesh is ever built."""
    from spectrinsic.scenes.budget import MAX_FACES
    from spectrinsic.scenes.mitsuba_parts import sphere

    per_sphere = len(sphere(np.zeros(3), 1.0)[1])
    per_ply = max(1, round((MAX_FACES * share - spheres * per_sphere) / references))
    total = references * per_ply + spheres * per_sphere
    ball = '<shape type="sphere"><point name="center" x="0" y="0" z="1"/></shape>'
    ply = '<shape type="ply"><string name="filename" value="big.ply"/></shape>'
    text = (
        '<scene version="3.0.0"><emitter type="point"><point name="position" x="0" y="0" z="2"/>'
        f'<rgb name="intensity" value="5"/></emitter>{ball * spheres}{ply * references}'
        '<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/>'
        '<integer name="height" value="6"/></film></sensor></scene>'
    )

    def plant(folder: Path) -> None:
        (folder / "big.ply").write_text(_ply_header(per_ply))

    refusal = _read(text, plant)
    assert isinstance(refusal, str), "a PLY without a body was read"
    assert ("holds at most" in refusal) == (total > MAX_FACES), (total, refusal)
