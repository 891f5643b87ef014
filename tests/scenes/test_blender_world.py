"""A .blend's World as light (issue 42): a background colour as a ``sky``, an Environment
Texture as an environment map. The files are built with bpy in a subprocess
(``make_world_blend.py``); the maps are written here with Mitsuba's ``Bitmap``.

Blender's equirectangular convention is written out below from Cycles' source
(``kernel/camera/projection.h``: ``equirectangular_range_to_direction`` with the range
``(−2π, π, −π, π)``): a map point (u, v), v = 0 the bottom row, is the direction
``φ = π − 2πu``, ``θ = π (1 − v)``, ``(sin θ cos φ, sin θ sin φ, cos θ)``, Z up. The tests hold
our rotation to it independently of how the reader derives it.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.errors import SceneError
from spectrinsic.mitsuba_import import import_mitsuba

from ._builders import build_blend

#: The maps' size (rows, columns).
ROWS, COLS = 32, 64
#: A map of value 1.5 + direction against Mitsuba's bilinear lookup at its own rows (i / (H − 1),
#: Blender's at (i + ½) / H): at most half a row (π / 2H = 0.049 rad for H = 32) apart, plus the
#: bilinear blend across a texel.
SMOOTH_TOLERANCE = 0.06
#: The colour route's round trip (``spectra/user_spectra.py``: 1.2e-3 on the sRGB cube).
UPLIFT = 2e-3


def blender_directions(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Cycles' direction of map point (u, v), v = 0 the bottom row (module docstring)."""
    phi, theta = np.broadcast_arrays(math.pi - 2 * math.pi * u, math.pi * (1 - v))
    return np.stack(
        [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1
    )


def texel_directions(rows: int, cols: int) -> np.ndarray:
    """``(rows, cols, 3)`` Blender directions of the texel centres, row 0 the image's top."""
    u = (np.arange(cols) + 0.5) / cols
    v = 1 - (np.arange(rows) + 0.5) / rows
    return blender_directions(u[None, :], v[:, None])


def patch_map() -> np.ndarray:
    """Black but for 2 x 2 texels of 200 around the direction (0, 1, 1)/√2 (+Y, 45° up):
    u = 1/4 (φ = π/2), v = 3/4 (θ = π/4): columns 15, 16, rows 7, 8 from the top."""
    image = np.zeros((ROWS, COLS, 3))
    image[7:9, 15:17] = 200.0
    return image


def write_map(path: Path, image: np.ndarray) -> None:
    mi = import_mitsuba()
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    mi.Bitmap(np.ascontiguousarray(image, np.float32)).write(str(path))


@pytest.fixture(scope="module")
def worlds(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("world")
    folder = root / "scene"
    (folder / "maps").mkdir(parents=True)
    write_map(folder / "maps" / "patch.exr", patch_map())
    write_map(folder / "maps" / "smooth.exr", 1.5 + texel_directions(ROWS, COLS))
    write_map(root / "outside.exr", patch_map())
    return build_blend("make_world_blend.py", folder)


def load(path: Path, **options):
    from spectrinsic.scenes.blender import load_blend

    return load_blend(path, **options)


@pytest.mark.blender
def test_a_background_colour_is_one_sky_of_that_radiance(worlds):
    """Color (0.8, 0.4, 0.2) at Strength 2.5 is a constant radiance 2.5 · (0.8, 0.4, 0.2) in
    linear Rec. 709 (sRGB primaries, D65): the sky's power × spectrum, integrated here with
    colour-science's CIE 1931 functions (luminance relative to Σ ȳ, the registry's unit), must
    have that colour's XYZ (colour-science's sRGB matrix), within the uplift's round trip."""
    import colour

    from spectrinsic.spectra import get_spectrum

    scene = load(worlds / "colour.blend")
    (sky,) = scene.lights
    assert (sky.kind, sky.name) == ("sky", "World")
    spectrum = get_spectrum(sky.spectrum)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    cmf = np.stack([np.interp(spectrum.wavelengths, cmfs.wavelengths, c) for c in cmfs.values.T])
    xyz = cmf @ (sky.power * spectrum.values) / cmf[1].sum()
    want = colour.models.RGB_COLOURSPACE_sRGB.matrix_RGB_to_XYZ @ (2.5 * np.array([0.8, 0.4, 0.2]))
    assert abs(xyz[1] / want[1] - 1) < UPLIFT
    np.testing.assert_allclose(xyz[:2] / xyz.sum(), want[:2] / want.sum(), atol=UPLIFT)


@pytest.mark.blender
def test_a_convex_cube_under_the_background_colour_returns_its_albedo_of_the_sky(worlds):
    """A furnace: under a uniform sky of radiance L every face of a convex Lambertian cube of
    albedo 0.8 sees only sky, so it returns 0.8 L, and the camera sees L itself around it
    (rgb3, 24², 16 spp; pixels whose neighbours all hit the cube, or all miss it, so no pixel
    blends the two; measured 0.8031 ± 0.0075, the sky exact)."""
    from scipy.ndimage import binary_erosion

    from spectrinsic.render import RenderSettings, render_scene

    result = render_scene(
        load(worlds / "colour.blend"), RenderSettings(16, modes=("rgb3",)), seed=1
    )
    image, mask = result.images["rgb3"].astype(np.float64), result.aovs["mask"]
    cube, sky = image[binary_erosion(mask)], image[binary_erosion(~mask)]
    error = 4 * cube.std(0, ddof=1) / np.sqrt(len(cube)) / cube.mean(0)
    np.testing.assert_allclose(sky, np.broadcast_to(sky[0], sky.shape), rtol=1e-6)
    assert np.all(np.abs(cube.mean(0) / sky[0] - 0.8) <= 0.8 * error), (
        cube.mean(0) / sky[0],
        error,
    )


@pytest.mark.blender
@pytest.mark.parametrize("stem", ["zero", "black"])
def test_a_dark_world_gives_no_light_and_says_nothing(worlds, stem, capsys, caplog):
    scene = load(worlds / f"{stem}.blend", validate=False)  # no light at all: validation refuses
    assert scene.lights == ()
    assert capsys.readouterr().err == "" and not caplog.records


@pytest.mark.blender
def test_an_environment_texture_is_a_map_of_its_file_sha_and_rotation(worlds):
    """Three channel lights of the image file inside the .blend's folder, its SHA-256, the
    Strength as scale (each channel's power its Rec. 709 luminance share × the scale), and the
    rotation: Mitsuba's local +x, +y, +z to Blender's +Y, +Z, +X (unturned); a Mapping turning
    Blender's look-up 90° about Z (POINT) turns the map by −90°: ``Rz(−90°)`` times that frame,
    multiplied out by hand."""
    from spectrinsic.scenes.envmaps import envmap_groups

    path = worlds / "maps" / "patch.exr"
    scene = load(worlds / "hdri.blend")
    assert [light.name for light in scene.lights] == ["HDRI.r", "HDRI.g", "HDRI.b"]
    (env,) = envmap_groups(scene)
    assert env.file == str(path.resolve())
    assert env.sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    np.testing.assert_allclose(env.rotation, [0, 0, 1, 1, 0, 0, 0, 1, 0], atol=1e-12)
    rec709_y = [0.2126729, 0.7151522, 0.0721750]
    np.testing.assert_allclose([light.power for light in scene.lights], rec709_y, rtol=UPLIFT)

    turned = load(worlds / "turned.blend")
    (env,) = envmap_groups(turned)
    assert Path(env.file).name == "smooth.exr"
    np.testing.assert_allclose(env.rotation, [1, 0, 0, 0, 0, -1, 0, 1, 0], atol=1e-6)
    np.testing.assert_allclose(
        [light.power for light in turned.lights], 2 * np.array(rec709_y), rtol=UPLIFT
    )


@pytest.mark.blender
@pytest.mark.parametrize(
    ("angle", "texture"),
    [(0.0, False), (0.7, False), (0.7, True)],
    ids=["none", "point", "texture"],
)
def test_mitsuba_reads_a_turned_map_where_blender_does(worlds, angle, texture):
    """Mitsuba's ``envmap`` under :func:`blender_map_rotation` against Blender's look-up: a
    map whose texels hold 1.5 + their own Blender direction evaluates, at a world direction d,
    to 1.5 + the direction Blender looks up: ``Rz(angle) d`` behind a POINT Mapping,
    ``Rz(−angle) d`` behind a TEXTURE one (Blender's ``node_mapping``: the rotation applied,
    or its transpose). A mirrored or quarter-turned convention misses by about 1."""
    from spectrinsic.scenes.blender_world import blender_map_rotation

    mi = import_mitsuba()
    rotation = np.reshape(blender_map_rotation(angle, texture=texture), (3, 3))
    to_world = np.eye(4)
    to_world[:3, :3] = rotation
    with mi.util.variant_context("scalar_rgb"):
        emitter = mi.load_dict(
            {
                "type": "envmap",
                "filename": str(worlds / "maps" / "smooth.exr"),
                "to_world": mi.ScalarTransform4f(to_world.tolist()),
            }
        )
        rng = np.random.default_rng(7)
        directions = rng.normal(size=(200, 3))
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        got = []
        for d in directions:
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*(-d))
            got.append(list(emitter.eval(si)))
    c, s = math.cos(angle), math.sin(angle) * (-1 if texture else 1)
    turn = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    np.testing.assert_allclose(np.array(got), 1.5 + directions @ turn.T, atol=SMOOTH_TOLERANCE)


@pytest.mark.blender
def test_the_map_lights_the_cube_faces_that_face_its_bright_patch(worlds):
    """A real render (24², rgb3): the map's one bright patch lies at +Y, 45° up (Blender's
    convention), so the unit cube's +Y and +Z faces receive it at cos 45° alike and the +X face
    only its edge (the patch spans ±6° about the +Y azimuth; a mirrored map would light −Y, a
    quarter turn +X, a flipped one −Z). No other light, no floor: a convex cube gets no
    interreflection."""
    from spectrinsic.render import RenderSettings, render_scene

    scene = load(worlds / "hdri.blend")
    result = render_scene(scene, RenderSettings(16, modes=("rgb3",)), seed=1)
    y = result.images["rgb3"][..., 1].astype(np.float64)
    normals, mask = result.aovs["normals"], result.aovs["mask"]
    face = {axis: y[mask & (normals @ np.eye(3)[i] > 0.9)].mean() for i, axis in enumerate("XYZ")}
    assert face["Y"] > 10 * face["X"] and face["Z"] > 10 * face["X"], face
    assert 0.7 < face["Y"] / face["Z"] < 1.4, face


@pytest.mark.blender
def test_a_sky_texture_is_refused_by_the_command_line_in_one_line(worlds, tmp_path, capsys):
    from spectrinsic.cli import main

    path = worlds / "sky.blend"
    rc = main(["-q", "render", str(path), "--modes", "rgb3", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert str(path) in err and "Sky Texture" in err and "--approximate" in err
    assert not (tmp_path / "o").exists()


@pytest.mark.blender
def test_approximate_takes_the_background_colour_and_says_so(worlds):
    """``--approximate``: the Sky Texture is left out and the Background's own colour
    (0.1, 0.2, 0.3) at Strength 2 taken, in one phrase; a Mix Shader World is dropped."""
    from spectrinsic.scenes.reading_notes import reading_notes

    scene = load(worlds / "sky.blend", approximate=True)
    (sky,) = scene.lights
    rgb = [float(c) for c in sky.spectrum.removeprefix("rgblight:").split(",")]
    np.testing.assert_allclose(rgb, [1 / 3, 2 / 3, 1], atol=1e-6)  # Blender's float32
    (phrase,) = scene.metadata["approximated"]
    assert "Sky Texture" in phrase and "own colour" in phrase
    assert len(reading_notes(scene)) == 1
    mixed = load(worlds / "mix.blend", approximate=True, validate=False)
    assert mixed.lights == () and "Mix Shader" in mixed.metadata["approximated"][0]


@pytest.mark.blender
def test_approximate_applies_to_blend_files_on_the_command_line(worlds, tmp_path, capsys):
    """``render x.blend --approximate`` reads the file with it (here the Mix Shader World is
    dropped, and the scene, left without light, is refused by validation before any render),
    and ``dataset --scenes x.blend --approximate`` records it."""
    import json

    from spectrinsic.cli import main
    from spectrinsic.pipeline.source_plan import files_source

    path = worlds / "mix.blend"
    args = ["render", str(path), "--approximate", "--modes", "rgb3", "--out", str(tmp_path / "o")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "needs at least one light" in err and "applies to" not in err
    assert json.loads(files_source([path], approximate=True))["approximate"] is True


@pytest.mark.blender
@pytest.mark.parametrize(
    ("stem", "says"),
    [
        ("tilted", "more than turn the map about Z"),
        ("mix", "Mix Shader"),
        ("packed", "packed in the .blend"),
        ("escape", "inside the .blend's folder"),
    ],
)
def test_other_worlds_are_refused_in_one_line(worlds, stem, says):
    with pytest.raises(SceneError, match=r"world '\w+'") as info:
        load(worlds / f"{stem}.blend")
    message = str(info.value)
    assert says in message and "\n" not in message and str(worlds) in message


@pytest.mark.blender
def test_a_sample_names_the_map_inside_the_blend_folder(worlds):
    """The sample's scene record names the map relative to the .blend's folder (no path of the
    machine that built it), as XML maps are named."""
    from spectrinsic.scenes.envmaps import portable_map_files
    from spectrinsic.scenes.model import scene_to_dict

    record = portable_map_files(scene_to_dict(load(worlds / "hdri.blend")), worlds)
    assert {light["file"] for light in record["lights"]} == {"maps/patch.exr"}
