"""Mitsuba XML shapes the probes of round 5 accepted oddly (task r5-probe2): a sphere of
negative radius and a mesh file with a NaN vertex."""

from __future__ import annotations

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
