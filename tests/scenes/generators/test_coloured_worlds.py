"""Generated worlds that exercise colour (issue 22): saturated and mixed lights, two-colour
pairs people can tell apart, and material ranges every generator obeys. No rendering."""

import math

import colour
import numpy as np
import pytest

from spectrinsic.errors import SceneError, SpectrumNotFoundError
from spectrinsic.scenes.generators import (
    GeneratorOptions,
    MaterialDistribution,
    generate,
    generated_scene_seed,
)
from spectrinsic.scenes.generators.base import family_of, scene_rngs
from spectrinsic.scenes.generators.lights import (
    TWO_COLOUR_XY,
    LightVolume,
    check_saturation,
    draw_lights,
)
from spectrinsic.scenes.generators.materials import check_ranges, munsell_chips
from spectrinsic.spectra import get_spectrum
from spectrinsic.spectra.coloured_lights import FILTER_FLOOR, filter_transmission

_VOLUME = LightVolume(lo=(0, 0, 1), hi=(1, 1, 2), focus=(0.5, 0.5, 0))
#: Scenes of the done-when set (``--count 200``).
COUNT = 200


def _xy_duv(name):
    """Independent colorimetry: colour-science's own sd_to_XYZ and Ohno 2013 Duv."""
    spd = get_spectrum(name)
    sd = colour.SpectralDistribution(dict(zip(spd.wavelengths, spd.values, strict=True)))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    xy = colour.XYZ_to_xy(colour.sd_to_XYZ(sd.copy().align(cmfs.shape), cmfs, method="Integration"))
    duv = colour.temperature.uv_to_CCT_Ohno2013(colour.xy_to_UCS_uv(xy))[1]
    return np.asarray(xy, float), float(duv)


def _set_lights(generator, saturation=None):
    """The lights of scenes 0..COUNT-1 of a generated set, as :func:`generate` draws them (the
    lights have their own child seed: geometry and camera do not change them)."""
    for i in range(COUNT):
        seed = generated_scene_seed(0, generator, i)
        family = family_of(seed)
        lights = draw_lights(
            scene_rngs(seed)["lights"], family, _VOLUME, free=lambda p: True, saturation=saturation
        )
        yield family, lights


@pytest.mark.parametrize("generator", ["rooms", "objects-on-ground"])
def test_a_third_of_coloured_lights_are_tinted_and_two_colours_are_far_apart(generator):
    duv, pairs = [], []
    for family, lights in _set_lights(generator):
        if family == "white":
            continue
        names = sorted({light.spectrum for light in lights})
        measured = {n: _xy_duv(n) for n in names}
        duv += [abs(measured[light.spectrum][1]) for light in lights]
        if family == "two-colour":
            assert len(names) == 2, names
            pairs.append(float(np.linalg.norm(measured[names[0]][0] - measured[names[1]][0])))
    assert np.mean(np.array(duv) >= 0.02) >= 1 / 3, np.mean(np.array(duv) >= 0.02)
    assert pairs and min(pairs) >= TWO_COLOUR_XY, min(pairs)


def test_light_saturation_range_keeps_only_lights_in_it():
    seen = 0
    for family, lights in list(_set_lights("rooms", saturation=(0.05, 0.3)))[:60]:
        for light in lights if family != "white" else ():
            assert 0.05 - 1e-4 <= abs(_xy_duv(light.spectrum)[1]) <= 0.3 + 1e-4, light.spectrum
            seen += 1
    assert seen > 20


@pytest.mark.parametrize("bad", [(0.2, 0.3), (0.05, 0.01), (-0.1, 0.1)])
def test_impossible_light_saturation_is_refused(bad):
    with pytest.raises(SceneError, match="light saturation"):
        check_saturation(bad)


def test_led_spectra_peak_where_asked_and_mix_their_terms():
    wl = np.arange(380.0, 781.0)
    one = get_spectrum("led:460/20").on(wl)
    assert wl[one.argmax()] == pytest.approx(460, abs=1)
    assert one[np.abs(wl - 460) > 40].max() < 0.02 * one.max()  # narrow band
    mix = get_spectrum("led:630/20@1+530/30@0.5").on(wl)
    # Ohno's LED shape peaks at 1, so the peak ratio is the ratio asked for
    assert mix[wl == 530][0] / mix[wl == 630][0] == pytest.approx(0.5, rel=0.02)
    with pytest.raises(SpectrumNotFoundError, match="PEAK/FWHM"):
        get_spectrum("led:blue")


def test_filtered_lamp_is_lamp_times_filter_transmission():
    lamp, out = get_spectrum("planck:3200K"), get_spectrum("filtered:planck:3200K|bandpass:520/80")
    wl = np.asarray(lamp.wavelengths)
    ratio = out.values / lamp.values
    t = filter_transmission("bandpass:520/80", wl)
    assert np.allclose(ratio / ratio.max(), t / t.max(), rtol=1e-9)
    assert t.min() == pytest.approx(FILTER_FLOOR, abs=1e-6) and t.max() == pytest.approx(
        1.0, abs=1e-6
    )
    # half transmission at centre +- FWHM/2, and a long-pass rises through its edge
    half = (filter_transmission("bandpass:520/80", np.array([480.0, 560.0])) - FILTER_FLOOR) / (
        1 - FILTER_FLOOR
    )
    assert np.allclose(half, 0.5)
    lp = filter_transmission("longpass:600/30", np.array([585.0, 600.0, 615.0]))
    assert lp[0] < 0.2 < lp[1] < 0.8 < lp[2]
    green = _xy_duv("filtered:planck:3200K|bandpass:520/80")
    assert green[1] > 0.05 and math.dist(green[0], (0.3127, 0.329)) > 0.2


@pytest.mark.parametrize("generator", ["rooms", "objects-on-ground"])
def test_chroma_range_is_obeyed_by_every_material_of_both_generators(generator):
    dist = MaterialDistribution(value_range=(2.0, 9.0), chroma_range=(2.0, 4.0))
    options = GeneratorOptions(width=16, height=16, materials=dist)
    chips = {n: (v, c) for n, v, c in munsell_chips()}
    used = set()
    for index in range(3):
        scene = generate(generator, root_seed=5, index=index, view=0, options=options)
        used |= {m.spectrum for m in scene.materials}
    assert len(used) > 5
    # a spectral texture's texels are convex mixes of chips drawn in the range
    bases = {b.split("*", 1)[1] for n in used if n.startswith("mix:") for b in n[4:].split("+")}
    flat = {n for n in used if not n.startswith("mix:")} | bases
    assert all(n in chips and 2.0 <= chips[n][1] <= 4.0 for n in flat), sorted(flat)


def test_a_range_with_no_chip_is_refused_in_one_line():
    with pytest.raises(SceneError, match="chroma in 50-60") as err:
        check_ranges((2.0, 9.0), (50.0, 60.0))
    assert "\n" not in str(err.value)


#: Rays per side for the framing measurement: finer than the generator's own 12 x 12 check.
_FRAMING_GRID = 24


def test_room_views_frame_furniture_and_objects():
    """>= 90 % of room views have >= 30 % of their rays (24 x 24, as pixels) on furniture and
    objects, measured independently of the generator's coarser check."""
    from spectrinsic.scenes.generators.camera import first_hits
    from spectrinsic.scenes.geometry import camera_rays

    options = GeneratorOptions(width=32, height=24)
    fractions = []
    for index in range(10):
        scene = generate("rooms", root_seed=3, index=index, view=0, options=options)
        c = scene.camera
        o, d = camera_rays(c.origin, c.target, c.up, c.fov_deg, c.width, c.height, n=_FRAMING_GRID)
        hit = first_hits(scene.meshes, o, d)
        furnished = np.array(
            [not m.name.startswith(("wall-", "floor", "ceiling")) for m in scene.meshes] + [False]
        )
        fractions.append(float(furnished[hit].mean()))
    assert np.mean(np.array(fractions) >= 0.3) >= 0.9, fractions


def test_rooms_have_furniture_beyond_boxes_and_objects_on_shelves():
    options = GeneratorOptions(width=16, height=16)
    kinds, on_boards = set(), 0
    for index in range(8):
        scene = generate("rooms", root_seed=4, index=index, view=0, options=options)
        kinds |= {m.name.rsplit("-", 1)[0] for m in scene.meshes}
        shelves = [m for m in scene.meshes if m.name.startswith("shelf")]
        for m in scene.meshes:
            z0, lo, hi = (
                float(m.vertices[:, 2].min()),
                m.vertices.min(axis=0),
                m.vertices.max(axis=0),
            )
            for s in shelves:
                slo, shi = s.vertices.min(axis=0), s.vertices.max(axis=0)
                inside = np.all(lo[:2] >= slo[:2]) and np.all(hi[:2] <= shi[:2])
                on_boards += bool(m is not s and inside and 0.01 < z0 < shi[2] - 0.01)
    assert {"round-table", "sofa", "lamp"} & kinds, kinds
    assert on_boards > 0


def test_sfu_lamps_behind_filters_with_a_data_directory(data_dir):
    from spectrinsic.scenes.generators.lights import draw_illuminant
    from spectrinsic.spectra import list_spectra

    sfu = tuple(list_spectra("sfu-illum", data_dir=data_dir))
    rng = np.random.default_rng(0)
    drawn = [draw_illuminant(rng, sfu, saturated=True) for _ in range(300)]
    filtered_sfu = [n for n in drawn if n.startswith("filtered:sfu-illum:")]
    assert filtered_sfu
    name = filtered_sfu[0]
    lamp_name, spec = name.removeprefix("filtered:").rsplit("|", 1)
    lamp, out = get_spectrum(lamp_name, data_dir=data_dir), get_spectrum(name, data_dir=data_dir)
    ratio = out.values / np.where(lamp.values > 0, lamp.values, np.nan)
    t = filter_transmission(spec, np.asarray(lamp.wavelengths))
    ok = np.isfinite(ratio)
    assert np.allclose(ratio[ok] / t[ok], (ratio[ok] / t[ok])[0], rtol=1e-9)


def test_spectral_texture_texels_are_valid_mixes_integrated_as_colour_science_does():
    from spectrinsic.scenes.generators.materials import PATTERNS, TEXTURE_STEPS, draw_palette
    from spectrinsic.scenes.generators.shapes import make_shape
    from spectrinsic.spectra import get_sensors, responses

    rng = np.random.default_rng(2)
    part = make_shape("ball", rng, "flat:0.5")
    palette = draw_palette(rng, MaterialDistribution(), 3)
    textured = PATTERNS["texture"](part, rng, palette)
    assert len(textured.palette) >= 5  # the weights vary over the surface
    cmf = get_sensors("cie1931")
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    for name in textured.palette:
        spd = get_spectrum(name)
        assert spd.values.min() >= 0.0 and spd.values.max() <= 1.0
        terms = (
            [t.split("*", 1) for t in name[4:].split("+")]
            if name.startswith("mix:")
            else [["1", name]]
        )
        weights = [float(w) for w, _ in terms]
        assert sum(weights) == pytest.approx(1.0) and all(
            w * TEXTURE_STEPS == round(w * TEXTURE_STEPS) for w in weights
        )
        # independent: colour-science's own arithmetic and integration of the texel spectrum
        sds = [
            colour.SpectralDistribution(
                dict(zip(get_spectrum(b).wavelengths, get_spectrum(b).values, strict=True))
            )
            for _, b in terms
        ]
        texel = sds[0] * weights[0]
        for w, sd in zip(weights[1:], sds[1:], strict=True):
            texel = texel + sd * w
        texel = texel.copy().align(cmfs.shape, extrapolator_kwargs={"method": "Constant"})
        expected = colour.sd_to_XYZ(texel, cmfs, method="Integration", k=1.0)
        got = responses(spd.on(cmf.wavelengths), cmf.curves, cmf.wavelengths)
        assert np.allclose(
            got / np.sum(cmf.curves[1]), expected / np.sum(cmfs.values[:, 1]), atol=1e-4
        ), name
