"""Mitsuba XML shapes the probes of round 5 accepted oddly (task r5-probe2): a sphere of
negative radius and a mesh file with a NaN vertex; and the side each shape and area light faces
under ``flip_normals`` and mirroring transforms, against Mitsuba's own (task r5-flip)."""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.errors import SceneError
from spectrinsic.mitsuba_import import import_mitsuba
from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml

CAMERA = (
    '<sensor type="perspective"><transform name="to_world"><lookat origin="0,0,3" '
    'target="0,0,0" up="0,1,0"/></transform><film type="hdrfilm"><integer name="width" '
    'value="8"/><integer name="height" value="8"/></film></sensor>'
)
LAMP = '<emitter type="point"><point name="position" value="0,0,2"/><rgb name="intensity" value="5"/></emitter>'


def _write(folder, body: str):
    path = folder / "s.xml"
    path.write_text(f'<scene version="3.0.0">{CAMERA}{LAMP}{body}</scene>')
    return path


@pytest.fixture
def mitsuba():
    """Mitsuba in ``scalar_rgb``, its variant restored after the test."""
    mi = import_mitsuba()
    before = mi.variant()
    mi.set_variant("scalar_rgb")
    yield mi
    if before is not None:
        mi.set_variant(before)


@pytest.mark.parametrize("radius, facing", [(1.0, 1.0), (-1.0, -1.0)])
def test_mitsubas_sphere_of_negative_radius_is_inside_out(mitsuba, radius, facing):
    """Why a negative radius is refused: Mitsuba's own sphere then has inward normals (seen
    from outside, its geometric normal points away from the viewer), so a one-sided BSDF is
    black, while a tessellation of ``centre + r * n`` would be lit and write inward normals."""
    scene = mitsuba.load_dict(
        {"type": "scene", "s": {"type": "sphere", "radius": radius, "bsdf": {"type": "diffuse"}}}
    )
    ray = mitsuba.Ray3f(mitsuba.Point3f(0, 0, 3), mitsuba.Vector3f(0, 0, -1))
    si = scene.ray_intersect(ray)
    assert float(si.t) == pytest.approx(2.0)  # the same surface, |r| = 1
    assert float(si.n[2]) == pytest.approx(facing)  # +1 towards the viewer, -1 away


@pytest.mark.parametrize("radius", ["-1", "0", "-0.5"])
def test_a_sphere_radius_not_above_zero_is_refused_in_one_line(tmp_path, radius):
    body = f'<shape type="sphere"><float name="radius" value="{radius}"/><bsdf type="diffuse"/></shape>'
    with pytest.raises(SceneError, match=r"sphere radius -?[0-9.]+; expected > 0") as info:
        load_mitsuba_xml(_write(tmp_path, body))
    assert "\n" not in str(info.value)


def test_a_sphere_area_light_of_negative_radius_is_refused_too(tmp_path):
    body = (
        '<shape type="sphere"><float name="radius" value="-0.2"/><emitter type="area">'
        '<rgb name="radiance" value="1"/></emitter></shape>'
        '<shape type="rectangle"><bsdf type="diffuse"/></shape>'
    )
    with pytest.raises(SceneError, match=r"sphere radius -0.2; expected > 0"):
        load_mitsuba_xml(_write(tmp_path, body))


def test_a_positive_sphere_radius_still_loads_outward(tmp_path):
    body = '<shape type="sphere"><float name="radius" value="0.5"/><bsdf type="diffuse"/></shape>'
    (mesh,) = load_mitsuba_xml(_write(tmp_path, body)).meshes
    import numpy as np

    v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    tri = v[f]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    assert np.all(np.einsum("ij,ij->i", normals, tri.mean(axis=1)) > 0)  # every face outward
    assert np.linalg.norm(v, axis=1) == pytest.approx(0.5)


@pytest.mark.parametrize("textured", [False, True])
def test_a_mesh_file_with_a_nan_vertex_is_named_by_its_file(tmp_path, textured):
    """The one line names the OBJ as the scene states it (relative to the scene's folder), not
    only the shape's id (``shape2``) that the scene-wide check after the transform knows."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "m.obj").write_text(
        "v 0 0 0\nv nan 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 3/2 4/3\nf 2/1 3/2 4/3\n"
    )
    texture = (
        '<texture type="bitmap" name="reflectance"><string name="filename" value="t.png"/></texture>'
        if textured
        else ""
    )
    if textured:
        from PIL import Image

        Image.new("RGB", (2, 2), (128, 64, 32)).save(tmp_path / "t.png")
    body = (
        '<shape type="obj"><string name="filename" value="sub/m.obj"/>'
        f'<bsdf type="diffuse">{texture}</bsdf></shape>'
    )
    with pytest.raises(SceneError) as info:
        load_mitsuba_xml(_write(tmp_path, body))
    message = str(info.value)
    assert message.count("'sub/m.obj'") == 1 and "\n" not in message
    # ours, or Mitsuba's own loader's (the textured path reads the file with it)
    assert ("NaN or infinite" if not textured else "invalid vertex position") in message


# Which side of a shape faces the camera, ours against Mitsuba's (task r5-flip): Mitsuba maps
# the normals of a rectangle, disk, cube and cylinder by the inverse transpose of their own
# to_world (a mirroring one keeps their side), a sphere's and a face-normal mesh file's follow
# the mirrored surface, an instance's mirroring keeps every side, and flip_normals turns it.
QUAD_OBJ = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n"
QUAD_V, QUAD_F = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]), [[0, 1, 2], [0, 2, 3]]
FACE_NORMALS = '<boolean name="face_normals" value="true"/>'
CYLINDER = '<point name="p0" x="0" y="0" z="-1"/><point name="p1" x="0" y="0" z="1"/>'
SHAPES = {
    "rectangle": ("rectangle", ""),
    "disk": ("disk", ""),
    "cube": ("cube", ""),
    "sphere": ("sphere", '<float name="radius" value="0.8"/>'),
    "cylinder": ("cylinder", CYLINDER + '<float name="radius" value="0.5"/>'),
    "obj": ("obj", '<string name="filename" value="quad.obj"/>'),
    "obj-vn": ("obj", '<string name="filename" value="quad_vn.obj"/>'),
    "obj-vn-face": ("obj", '<string name="filename" value="quad_vn.obj"/>' + FACE_NORMALS),
    "ply": ("ply", '<string name="filename" value="quad.ply"/>'),
    "ply-nx": ("ply", '<string name="filename" value="quad_nx.ply"/>'),
    "serialized": ("serialized", '<string name="filename" value="quad.serialized"/>'),
    "serialized-n": ("serialized", '<string name="filename" value="quad_n.serialized"/>'),
    # flagged 0x0010 (face normals) too: Mitsuba still shades with the stored ones
    "serialized-n16": ("serialized", '<string name="filename" value="quad_n16.serialized"/>'),
}


def _mesh_files(folder) -> None:
    """The quad of :data:`QUAD_OBJ` in every file format, with and without stored normals
    (+z): what Mitsuba then shades with under a mirroring to_world (:data:`SHAPES`)."""
    (folder / "quad.obj").write_text(QUAD_OBJ)
    (folder / "quad_vn.obj").write_text(
        QUAD_OBJ.replace("f 1 2 3\nf 1 3 4", "vn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1")
    )
    for name, normals in (("quad", False), ("quad_nx", True)):
        extra = "property float nx\nproperty float ny\nproperty float nz\n" if normals else ""
        rows = "".join(
            " ".join(map(str, [*v, *([0, 0, 1] if normals else [])])) + "\n" for v in QUAD_V
        )
        (folder / f"{name}.ply").write_text(
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
            f"property float z\n{extra}element face 2\nproperty list uchar int vertex_indices\n"
            f"end_header\n{rows}3 0 1 2\n3 0 2 3\n"
        )
        (folder / f"{name.replace('_nx', '_n')}.serialized").write_bytes(_serialized(normals))
    (folder / "quad_n16.serialized").write_bytes(_serialized(True, 0x0010))


def _serialized(normals: bool, more_flags: int = 0) -> bytes:
    """The quad as a Mitsuba ``.serialized`` file (format 4, single precision; flag 0x0001 and
    +z vertex normals with *normals*; *more_flags* besides), as
    tests/scenes/test_mitsuba_parser.py writes one."""
    import struct
    import zlib

    flags = 0x1000 | (0x0001 if normals else 0) | more_flags
    body = struct.pack("<I", flags) + b"quad\0" + struct.pack("<QQ", 4, 2)
    body += QUAD_V.astype("<f4").tobytes()
    body += np.tile([0, 0, 1], (4, 1)).astype("<f4").tobytes() if normals else b""
    body += np.asarray(QUAD_F, "<u4").tobytes()
    out = struct.pack("<HH", 0x041C, 4) + zlib.compress(body)
    return out + struct.pack("<Q", 0) + struct.pack("<I", 1)


MIRRORS = {"none": "", "x": '<scale x="-1"/>', "z": '<scale z="-1"/>'}
#: The camera's ray (above, looking down -z): off the axes, so it meets one triangle.
ORIGIN, DOWN = np.array([0.05, 0.03, 3.0]), np.array([0.0, 0.0, -1.0])


def _shape(plugin: str, params: str, transform: str, flip: bool) -> str:
    turn = '<rotate x="1" angle="90"/>' if plugin == "cylinder" else ""  # its side up
    flipped = '<boolean name="flip_normals" value="true"/>' if flip else ""
    return (
        f'<shape type="{plugin}">{params}{flipped}<bsdf type="diffuse"/>'
        f'<transform name="to_world">{turn}{transform}</transform></shape>'
    )


def _instanced(shape: str, transform: str) -> str:
    return (
        f'<shape type="shapegroup" id="group">{shape}</shape><shape type="instance">'
        f'<ref id="group"/><transform name="to_world">{transform}</transform></shape>'
    )


def _our_normal(path) -> np.ndarray:
    """The unit normal (right-hand rule on its corners) of our first triangle on the ray."""
    hits = []
    for mesh in load_mitsuba_xml(path).meshes:
        tri = np.asarray(mesh.vertices)[np.asarray(mesh.faces)]
        e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        p = np.cross(DOWN, e2)
        det = np.einsum("ij,ij->i", e1, p)
        s = ORIGIN - tri[:, 0]
        q = np.cross(s, e1)
        with np.errstate(divide="ignore", invalid="ignore"):  # Möller–Trumbore
            u, v = np.einsum("ij,ij->i", s, p) / det, q @ DOWN / det
            t = np.einsum("ij,ij->i", e2, q) / det
            hit = (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)  # NaN (edge-on): no hit
        n = np.cross(e1, e2)
        hits += [(t[i], n[i] / np.linalg.norm(n[i])) for i in np.flatnonzero(hit)]
    return min(hits, key=lambda h: h[0])[1]


def _mitsubas_normal(mi, path) -> np.ndarray:
    si = mi.load_file(str(path)).ray_intersect(mi.Ray3f(mi.Point3f(ORIGIN), mi.Vector3f(DOWN)))
    assert bool(si.is_valid())
    return np.array(si.sh_frame.n, float)


@pytest.mark.parametrize("flip", [False, True], ids=["plain", "flipped"])
@pytest.mark.parametrize("mirror", list(MIRRORS))
@pytest.mark.parametrize("name", list(SHAPES))
def test_our_triangles_face_the_side_mitsubas_shape_faces(tmp_path, mitsuba, name, mirror, flip):
    """Under ``flip_normals`` and a mirroring ``to_world``, our triangle under the camera's
    ray turns the way Mitsuba's shading normal does (within its tessellation: same sign of z,
    close direction); before task r5-flip a mirrored winding turned every shape."""
    _mesh_files(tmp_path)
    path = _write(tmp_path, _shape(*SHAPES[name], MIRRORS[mirror], flip))
    theirs, ours = _mitsubas_normal(mitsuba, path), _our_normal(path)
    assert abs(theirs[2]) > 0.9  # the ray meets the shape face on (test can see a flip)
    assert ours @ theirs > 0.95


@pytest.mark.parametrize("name", ["rectangle", "sphere", "obj", "ply-nx"])
def test_an_instances_mirroring_keeps_the_side(tmp_path, mitsuba, name):
    """An instance's mirroring ``to_world`` never turns its shapes (Mitsuba maps the normals
    by its inverse transpose), not even a sphere's or a mesh file's."""
    _mesh_files(tmp_path)
    path = _write(tmp_path, _instanced(_shape(*SHAPES[name], "", False), MIRRORS["x"]))
    theirs, ours = _mitsubas_normal(mitsuba, path), _our_normal(path)
    assert theirs[2] > 0.9 and ours @ theirs > 0.95


@pytest.mark.parametrize("flip", [False, True], ids=["plain", "flipped"])
@pytest.mark.parametrize("mirror", [*MIRRORS, "y-turned"])
def test_an_area_light_emits_on_mitsubas_side(tmp_path, mitsuba, mirror, flip):
    """A rectangle's ``area`` emitter shines to the side of Mitsuba's normal (the inverse
    transpose of its to_world applied to +z: ``u × v / det``), which our light's direction
    names, under mirroring transforms too (``y-turned``: a mirror in y seen along z)."""
    turned = '<rotate x="1" angle="90"/><scale y="-1"/><rotate x="1" angle="-90"/>'
    transform = turned if mirror == "y-turned" else MIRRORS[mirror]
    flipped = '<boolean name="flip_normals" value="true"/>' if flip else ""
    far = (
        '<shape type="rectangle"><transform name="to_world"><translate z="-5"/></transform></shape>'
    )
    lamp = (
        f'<shape type="rectangle">{flipped}<emitter type="area"><rgb name="radiance" value="1"/>'
        f'</emitter><transform name="to_world">{transform}</transform></shape>'
    )
    path = _write(tmp_path, lamp + far)
    scene = mitsuba.load_file(str(path))
    si = scene.ray_intersect(mitsuba.Ray3f(mitsuba.Point3f(ORIGIN), mitsuba.Vector3f(DOWN)))
    seen = float(si.emitter(scene).eval(si)[0])  # radiance towards the ray's origin, above
    (light,) = [x for x in load_mitsuba_xml(path).lights if x.kind == "area"]
    assert (seen > 0) == (light.direction[2] > 0.99) and abs(light.direction[2]) > 0.99


@pytest.mark.parametrize("mirror", ["x", "z"])
def test_the_rendered_normals_of_a_mirrored_rectangle_are_mitsubas(tmp_path, mitsuba, mirror):
    """End to end: the normals map of our render (``geometry.exr``'s ``normals``) of a
    mirrored rectangle filling the view is Mitsuba's own ``aov`` ``sh_normal`` of the file."""
    from spectrinsic.render import RenderSettings, render_scene

    body = _shape("rectangle", "", f"<scale value='4'/>{MIRRORS[mirror]}", False)
    path = _write(tmp_path, body)
    aov = mitsuba.load_dict({"type": "aov", "aovs": "n:sh_normal"})
    theirs = np.asarray(mitsuba.render(mitsuba.load_file(str(path)), integrator=aov, spp=1))
    settings = RenderSettings(1, modes=("rgb3",), max_depth=2)
    ours = render_scene(load_mitsuba_xml(path), settings, seed=0).aovs["normals"]
    assert ours.shape[:2] == theirs.shape[:2] == (8, 8)
    np.testing.assert_allclose(ours, theirs[..., -3:], atol=1e-5)
    assert abs(ours[..., 2]).min() > 0.999  # the whole view on the rectangle
