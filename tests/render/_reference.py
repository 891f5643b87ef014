"""Mitsuba's own spectral ``path`` render as the independent reference of the XML box tests
(tests/render/test_glass.py, test_tinted_glass.py, test_xml_box_every_surface.py): the box
they share (:func:`box_xml`), the glass mesh both renderers trace, the band path's and
Mitsuba's CIE XYZ images, and their comparison per 8 × 8 block against the spread of
independent seeds (:func:`assert_matches_mitsuba`).

A helper module, not a conftest: its functions take arguments (scene, file, spp, seed), and
tests/test_test_layout.py checks only ``test_*.py`` files.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.render.result import RenderResult
from spectrinsic.scenes.model import Scene
from tests.scenes._cornell import box_walls

__all__ = [
    "SEEDS",
    "RES",
    "FALSE_ALARM",
    "CAMERA_Y",
    "FOV",
    "SMOOTH_GLASS",
    "box_xml",
    "assert_matches_mitsuba",
    "ICO_V",
    "ICO_F",
    "icosahedron_obj",
    "blocks",
    "cie_1931",
    "y_normalisation",
    "bands_xyz",
    "ours_xyz",
    "mitsuba_xyz",
    "assert_blocks_agree",
]

#: Independent seeds per renderer, whose spread gives each block's standard error.
SEEDS = 16
#: Image side of the boxes (pixels): 4 × 4 blocks of 8 × 8.
RES = 32
#: Family-wise false-alarm rate of the 48 block-channel comparisons.
FALSE_ALARM = 1e-3
#: The box's camera: at (0, CAMERA_Y, 1) looking along +y, vertical field of view FOV degrees.
CAMERA_Y, FOV = -3.5, 40
#: The box's smooth BK7 glass (``id="glass"``: a test swaps it for another by replacing it).
SMOOTH_GLASS = '<bsdf type="dielectric" id="glass"><string name="int_ior" value="bk7"/></bsdf>'

_BOX = """<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="6"/></integrator>
  <bsdf type="diffuse" id="white"><spectrum name="reflectance" value="0.7"/></bsdf>
{bsdfs}
  {glass}
  <bsdf type="conductor" id="mirror"><string name="material" value="none"/></bsdf>
{emitters}{walls}
{inside}
  <shape type="rectangle" id="lamp">
    <bsdf type="diffuse"><spectrum name="reflectance" value="0"/></bsdf>
    <transform name="to_world">
      <scale value="0.3"/><rotate x="1" angle="180"/><translate value="0 0 1.99"/>
    </transform>
    <emitter type="area">
      <spectrum name="radiance" value="360:4, 450:5, 550:6, 650:7, 830:8"/></emitter>
  </shape>
  <sensor type="perspective">
    <float name="fov" value="{fov:g}"/>
    <transform name="to_world"><lookat origin="0, {camera_y:g}, 1" target="0, 0, 1" up="0, 0, 1"/></transform>
    <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
    <film type="hdrfilm"><integer name="width" value="{res}"/><integer name="height" value="{res}"/>
    </film>
  </sensor>
</scene>
"""


def box_xml(
    *, bsdfs: str, floor: str, left: str, mirror: tuple[str, str], inside: str, emitters: str = ""
) -> str:
    """The Mitsuba XML box the tests share: a 2 × 2 × 2 room (floor z = 0, back wall y = 1,
    open towards the camera), white ceiling and back, a ``green`` right wall, a mirror
    ``looking-glass`` (*mirror*: its scale and centre) before the back wall, a ceiling lamp,
    the :data:`SMOOTH_GLASS` ``glass``, the camera of :data:`CAMERA_Y` and :data:`FOV`,
    RES × RES pixels. *bsdfs* (XML lines) declare ``green`` and the ids *floor* and *left*
    name besides ``white``; *inside*, the shapes in the room; *emitters*, lines of them."""
    scale, centre = mirror
    looking_glass = f"""  <shape type="rectangle" id="looking-glass"><ref id="mirror"/>
    <transform name="to_world">
      <scale value="{scale}"/><rotate x="1" angle="90"/><translate value="{centre}"/>
    </transform>
  </shape>
"""
    walls = box_walls(floor=floor, left=left, before_back=looking_glass)
    return _BOX.format(
        bsdfs=bsdfs, glass=SMOOTH_GLASS, emitters=emitters, walls=walls, inside=inside,
        fov=FOV, camera_y=CAMERA_Y, res=RES,
    )  # fmt: skip


#: A flat-shaded icosahedron of circumradius 1: the same triangles in both renderers (an
#: analytic ``sphere`` is triangulated by spectrinsic, and refraction would see the facets).
_T = (1 + 5**0.5) / 2
ICO_V = np.array(
    [[-1, _T, 0], [1, _T, 0], [-1, -_T, 0], [1, -_T, 0], [0, -1, _T], [0, 1, _T],
     [0, -1, -_T], [0, 1, -_T], [_T, 0, -1], [_T, 0, 1], [-_T, 0, -1], [-_T, 0, 1]]
) / np.hypot(1, _T)  # fmt: skip
ICO_F = [
    [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
    [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
    [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1],
]  # fmt: skip


def icosahedron_obj(*, uv: bool = False) -> str:
    """The icosahedron as OBJ text; with *uv*, spherical texture coordinates per vertex
    (u the azimuth, v the polar angle, each in [0, 1]) for a bump map on it."""
    obj = "".join(f"v {x:.9f} {y:.9f} {z:.9f}\n" for x, y, z in ICO_V)
    if not uv:
        return obj + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in ICO_F)
    u = np.arctan2(ICO_V[:, 1], ICO_V[:, 0]) / (2 * np.pi) + 0.5
    v = np.arccos(np.clip(ICO_V[:, 2], -1.0, 1.0)) / np.pi
    obj += "".join(f"vt {a:.9f} {b:.9f}\n" for a, b in zip(u, v, strict=True))
    return obj + "".join(
        f"f {a + 1}/{a + 1} {b + 1}/{b + 1} {c + 1}/{c + 1}\n" for a, b, c in ICO_F
    )


def blocks(image: np.ndarray) -> np.ndarray:
    """``(4, 4, 3)`` means of the 8 × 8 blocks of a 32 × 32 image."""
    return image.reshape(RES // 8, 8, RES // 8, 8, 3).mean(axis=(1, 3))


def cie_1931() -> tuple[np.ndarray, np.ndarray]:
    """colour-science's CIE 1931 2° functions on Mitsuba's 1 nm grid 360–830 nm: the
    wavelengths (nm) and ``(471, 3)`` x̄, ȳ, z̄."""
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy()
    cmfs = cmfs.align(colour.SpectralShape(360, 830, 1))
    return np.asarray(cmfs.wavelengths), np.asarray(cmfs.values)


@functools.cache
def y_normalisation() -> float:
    """∫ȳ dλ on Mitsuba's 1 nm grid 360–830 nm: its spectral XYZ film divides by it
    (``MI_CIE_Y_NORMALIZATION``); spectrinsic's raw channels are ``∫ L x̄ dλ`` unnormalised."""
    return float(cie_1931()[1][:, 1].sum())


def bands_xyz(result: RenderResult) -> np.ndarray:
    """``(H, W, 3)`` CIE XYZ of a render's ``bands31`` raw channels, through the render's own
    ``to_xyz`` matrix."""
    to_xyz = np.asarray(result.meta["to_xyz"]["bands31"], float)
    return np.einsum("hwk,ck->hwc", result.raw["bands31"], to_xyz)


def ours_xyz(
    scene: Scene, spp: int, seed: int, *, per_light: bool = False
) -> tuple[np.ndarray, RenderResult]:
    """The band path's CIE XYZ image of *scene* (its ``bands31`` raw channels through the
    render's own ``to_xyz``, depth 6 as the XML's ``path``) and the render's result."""
    settings = RenderSettings(spp, modes=("bands31",), max_depth=6, per_light=per_light)
    result = render_scene(scene, settings, seed=seed)
    return bands_xyz(result), result


def mitsuba_xyz(path: Path, spp: int) -> list[np.ndarray]:
    """Mitsuba's own spectral ``path`` render of the file at *path* (film CIE XYZ, box
    filter, as spectrinsic's pixels), one image per seed, in spectrinsic's units."""
    from spectrinsic.mitsuba_import import import_mitsuba
    from spectrinsic.render.base.variants import choose_variant

    mi = import_mitsuba()
    mi.set_variant(choose_variant("spectral"))
    xyz = path.with_name("xyz.xml")
    xyz.write_text(
        path.read_text().replace(
            '<film type="hdrfilm">',
            '<film type="hdrfilm"><string name="pixel_format" value="xyz"/><rfilter type="box"/>',
        )
    )
    loaded = mi.load_file(str(xyz))
    scale = y_normalisation()
    return [
        np.asarray(mi.render(loaded, spp=spp, seed=s), float)[..., :3] * scale for s in range(SEEDS)
    ]


def assert_blocks_agree(ours: np.ndarray, theirs: np.ndarray, *, max_t: float = np.inf) -> None:
    """Per block and channel of ``(SEEDS, 4, 4, 3)`` block means, the two renderers agree within
    t standard errors of the difference, from the spread of the seeds (t: Student's quantile,
    SEEDS − 1 degrees of freedom, for a family-wise false alarm of FALSE_ALARM over the
    comparisons, at most *max_t*), and each standard error is below 10 % of the block mean (the
    test can see)."""
    from scipy.stats import t as student

    stderr = np.hypot(ours.std(axis=0, ddof=1), theirs.std(axis=0, ddof=1)) / np.sqrt(SEEDS)
    diff = ours.mean(axis=0) - theirs.mean(axis=0)
    bound = min(student.ppf(1 - FALSE_ALARM / (2 * diff.size), df=SEEDS - 1), max_t)
    assert np.all(np.abs(diff) <= bound * stderr), np.abs(diff / stderr).max()
    assert np.all(stderr < 0.1 * theirs.mean(axis=0)), (stderr / theirs.mean(axis=0)).max()


def assert_matches_mitsuba(
    scene: Scene, path: Path, spp: int, mitsuba_spp: int, *, max_t: float = np.inf
) -> list[RenderResult]:
    """The band path's renders of *scene* (seeds 0 to SEEDS − 1, *spp* each), once their
    blocks agree with Mitsuba's own renders of the file at *path* (*mitsuba_spp* each) as
    :func:`assert_blocks_agree` asks."""
    runs = [ours_xyz(scene, spp, seed) for seed in range(SEEDS)]
    ours = np.stack([blocks(image) for image, _ in runs])
    theirs = np.stack([blocks(image) for image in mitsuba_xyz(path, mitsuba_spp)])
    assert_blocks_agree(ours, theirs, max_t=max_t)
    return [result for _, result in runs]
