"""Property-based tests of the input surfaces (issue 36): every input builds or is refused.

Spectrum names and the light and material mappings of a scene file are drawn by hypothesis
(bounded examples, ``derandomize=True``: the same examples on every run, so the suite is
deterministic in ``make test``). Each input must either give a valid, finite result or raise a
:class:`~spectrinsic.errors.SpectrinsicError` whose message is one line: never another
exception (a traceback for the user) and never a NaN. ``make test-properties`` runs many more
examples (``SPECTRINSIC_PROPERTY_EXAMPLES``).
"""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import numpy as np
import pytest
import yaml

hypothesis = pytest.importorskip("hypothesis", reason="hypothesis is in the dev extra")
st = pytest.importorskip("hypothesis.strategies")

from spectrinsic.errors import SpectrinsicError  # noqa: E402
from spectrinsic.scenes import load_scene  # noqa: E402
from spectrinsic.scenes.model import LIGHT_FIELDS  # noqa: E402
from spectrinsic.spectra import get_spectrum  # noqa: E402
from spectrinsic.spectra.illuminants import VISIBLE_SHARE, visible_share  # noqa: E402

#: Examples per property in ``make test`` (each property well under 10 s on one core).
EXAMPLES = int(os.environ.get("SPECTRINSIC_PROPERTY_EXAMPLES", "60"))
SETTINGS = hypothesis.settings(
    max_examples=EXAMPLES,
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=[hypothesis.HealthCheck.too_slow],
)

#: Numbers where bugs live: 0, tiny, huge, non-finite, negative, and ordinary values.
EDGE_NUMBERS = st.sampled_from(
    [0, 1, -1, 0.5, 1e-300, 1e-21, 1e-20, 1e20, 1e21, 1e38, 1e300, math.inf, -math.inf, math.nan]
)
NUMBERS = st.one_of(EDGE_NUMBERS, st.floats(allow_nan=True, allow_infinity=True), st.integers())
NUMBER_TEXT = st.one_of(
    st.integers(-10, 2000).map(str),
    st.floats(-1e3, 1e4, allow_nan=False).map(lambda x: f"{x:g}"),
    st.sampled_from(["inf", "nan", "1e400", "-0", "", "x", "1e-300"]),
)


def _spectrum_names() -> st.SearchStrategy[str]:
    led = st.builds(lambda p, w: f"led:{p}/{w}", NUMBER_TEXT, NUMBER_TEXT)
    flat = NUMBER_TEXT.map(lambda v: f"flat:{v}")
    planck = NUMBER_TEXT.map(lambda t: f"planck:{t}K")
    daylight = NUMBER_TEXT.map(lambda t: f"daylight:{t}K")
    shape = st.sampled_from(["bandpass", "longpass", "shortpass", "notch"])
    lamp = st.sampled_from(["cie:A", "planck:3000K", "flat:0.5", "led:460/20", "cie:D65"])
    filtered = st.builds(
        lambda lamp, s, a, b: f"filtered:{lamp}|{s}:{a}/{b}", lamp, shape, NUMBER_TEXT, NUMBER_TEXT
    )
    mix = st.builds(lambda w, v: f"mix:{w}*flat:{v}", NUMBER_TEXT, NUMBER_TEXT)
    named = st.sampled_from(
        [
            "cie:D65",
            "cie:FL11",
            "munsell:5R 4/14",
            "munsell:#12",
            "colorchecker:dark skin",
            "nope:1",
        ]
    )
    return st.one_of(led, flat, planck, daylight, filtered, mix, named, st.text(max_size=20))


def _refused_in_one_line(exc: BaseException) -> None:
    assert isinstance(exc, SpectrinsicError), f"{type(exc).__name__}: {exc}"
    assert "\n" not in str(exc) and str(exc).strip(), repr(str(exc))


@SETTINGS
@hypothesis.given(name=_spectrum_names())
def test_a_spectrum_name_gives_a_valid_spectrum_or_one_line(name):
    try:
        spectrum = get_spectrum(name)
    except Exception as exc:  # noqa: BLE001 - the property is about which exceptions escape
        _refused_in_one_line(exc)
        return
    values = np.asarray(spectrum.values, float)
    assert values.shape == np.shape(spectrum.wavelengths) and np.isfinite(values).all()
    assert spectrum.kind in ("reflectance", "illuminant")
    if spectrum.kind == "reflectance":
        assert values.min() >= 0 and values.max() <= 1 + 1e-9
    else:
        assert visible_share(np.asarray(spectrum.wavelengths, float), values) >= VISIBLE_SHARE


#: A scene file with one ground quad; its light and material come from the strategies.
BASE = {
    "name": "quad",
    "meshes": [
        {
            "name": "ground",
            "vertices": [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]],
            "faces": [[0, 1, 2], [0, 2, 3]],
            "material": "m",
        }
    ],
    "camera": {"origin": [0, -3, 2], "target": [0, 0, 0], "width": 16, "height": 16},
}
VECTORS = st.one_of(
    st.lists(NUMBERS, min_size=3, max_size=3),
    st.lists(st.integers(-3, 3), min_size=0, max_size=4),
    st.just("up"),
)
LIGHT_SPECTRA = st.sampled_from(
    ["cie:D65", "planck:3000K", "led:460/20", "led:1000/20", "flat:0.5", "nope"]
)


def _lights() -> st.SearchStrategy[dict]:
    """Lights with the keys their kind uses, each value often valid and sometimes an edge
    case, and sometimes a key of another kind or an unknown kind."""
    valid = {
        "position": st.sampled_from([[0, 0, 2], [1, -1, 2.5]]),
        "direction": st.sampled_from([[0, 0, -1], [0.3, 0.2, -1]]),
        "size": st.sampled_from([[1, 1], [0.5, 2]]),
        "cutoff_deg": st.sampled_from([30, 90]),
        "radius": st.sampled_from([0.1, 0.4]),
    }
    odd = {
        "position": VECTORS,
        "direction": VECTORS,
        "size": st.lists(NUMBERS, min_size=2, max_size=2),
        "cutoff_deg": NUMBERS,
        "radius": NUMBERS,
    }

    @st.composite
    def light(draw: st.DrawFn) -> dict:
        kind = draw(st.sampled_from([*LIGHT_FIELDS, *LIGHT_FIELDS, "sun"]))
        entry = {
            "kind": kind,
            "spectrum": draw(LIGHT_SPECTRA),
            "power": draw(st.one_of(st.sampled_from([4, 0.5, 100.0]), NUMBERS)),
        }
        for key in LIGHT_FIELDS.get(kind, ("position",)):
            entry[key] = draw(st.one_of(valid[key], valid[key], odd[key]))
        if draw(st.integers(0, 4)) == 0:  # a key of another kind
            key = draw(st.sampled_from(list(valid)))
            entry.setdefault(key, draw(valid[key]))
        return entry

    return light()


def _materials() -> st.SearchStrategy[object]:
    mapping = st.fixed_dictionaries(
        {"kind": st.sampled_from(["diffuse", "plastic", "conductor", "textured", "glass"])},
        optional={
            "spectrum": st.sampled_from(["flat:0", "flat:0.5", "cie:D65", "munsell:5R 4/14"]),
            "ior": NUMBERS,
            "roughness": NUMBERS,
            "metal": st.sampled_from(["Au", "Cu", "Xx"]),
            "basis": st.lists(st.sampled_from(["flat:0", "flat:0.5", "flat:2"]), max_size=5),
            "pattern": st.sampled_from(["rings", "weave", "noise", "dots"]),
            "size": st.one_of(st.integers(-2, 300), NUMBERS),
            "seed": st.one_of(st.integers(-2, 2**70), NUMBERS),
        },
    )
    return st.one_of(st.sampled_from(["flat:0", "flat:1e-300", "mix:0*flat:0.5", 7]), mapping)


def _load(doc: dict) -> None:
    """load_scene of *doc* written as YAML: a valid scene, or a one-line refusal."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.yaml"
        path.write_text(yaml.safe_dump(doc))
        try:
            scene = load_scene(path)
        except Exception as exc:  # noqa: BLE001 - the property is about which exceptions escape
            _refused_in_one_line(exc)
            return
    for light in scene.lights:
        assert math.isfinite(light.power) and light.power > 0
        assert np.isfinite(np.asarray(light.position, float)).all()


@SETTINGS
@hypothesis.given(light=_lights())
def test_a_light_mapping_builds_or_is_refused_in_one_line(light):
    _load({**BASE, "materials": {"m": "flat:0.5"}, "lights": [light]})


@SETTINGS
@hypothesis.given(material=_materials())
def test_a_material_mapping_builds_or_is_refused_in_one_line(material):
    light = {"kind": "point", "spectrum": "cie:D65", "power": 4, "position": [0, 0, 2]}
    _load({**BASE, "materials": {"m": material}, "lights": [light]})


#: The numeric fields of a camera model, each drawn valid or as an edge case.
_CAMERA_NUMBERS = {
    "gain_e_per_dn": st.one_of(st.just(0.5), NUMBERS),
    "full_well_e": st.one_of(st.just(40000.0), NUMBERS),
    "read_noise_e": st.one_of(st.just(3.0), NUMBERS),
    "adc_bits": st.one_of(st.sampled_from([12, 14, 12.5, 16.0, 7, 17]), NUMBERS),
    "iso": st.one_of(st.just(100.0), NUMBERS),
    "exposure_target": st.one_of(st.just(0.5), NUMBERS),
    "electrons_per_unit": st.one_of(st.none(), NUMBERS),
    "exposure_time_s": st.one_of(st.just(0.01), NUMBERS),
    "prnu": st.one_of(st.sampled_from([0.0, 0.01, 0.999, 1.0, 1e9]), NUMBERS),
    "dsnu_e": st.one_of(st.just(0.0), NUMBERS),
}


@SETTINGS
@hypothesis.given(values=st.fixed_dictionaries({}, optional=_CAMERA_NUMBERS))
def test_a_camera_model_is_finite_and_whole_or_refused_in_one_line(values):
    from spectrinsic.spectra.camera_model import CameraModel

    try:
        model = CameraModel(
            name="drawn",
            sensitivities="camera:Nikon 5100 (NPL)",
            **{"gain_e_per_dn": 0.5, "full_well_e": 4e4, "read_noise_e": 3.0, **values},
        )
    except Exception as exc:  # noqa: BLE001 - the property is about which exceptions escape
        _refused_in_one_line(exc)
        return
    numbers = [v for v in vars(model).values() if isinstance(v, int | float)]
    assert all(math.isfinite(v) for v in numbers)
    assert isinstance(model.adc_bits, int) and 0 <= model.prnu < 1
    assert 0 < model.gain < math.inf and 0 < model.white_level_dn <= 2**model.adc_bits - 1


#: One CSV spectrum file: a wavelength column and one value column, cells drawn as text.
_CSV_UNITS = st.sampled_from(["[%]", "[1]", "[W/m2/nm]", "[a.u.]", "", "[furlongs]"])


@SETTINGS
@hypothesis.given(
    unit=_CSV_UNITS,
    start=st.sampled_from(["380", "400", "420", "nan", "x"]),
    cells=st.lists(NUMBER_TEXT, min_size=0, max_size=8),
)
def test_a_csv_spectrum_gives_a_valid_spectrum_or_one_line(unit, start, cells):
    rows = [f"{start},{cells[0] if cells else '50'}"]
    rows += [f"{450 + 50 * i},{c}" for i, c in enumerate(cells[1:])]
    rows.append(f"720,{cells[-1] if cells else '50'}")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "drawn.csv"
        path.write_text(f"wavelength [nm],paint {unit}\n" + "\n".join(rows) + "\n")
        try:
            spectrum = get_spectrum(f"csv:{path}#paint")
        except Exception as exc:  # noqa: BLE001 - the property is about which exceptions escape
            _refused_in_one_line(exc)
            return
    values = np.asarray(spectrum.values, float)
    assert np.isfinite(values).all() and values.min() >= 0
    if spectrum.kind == "reflectance":
        assert values.max() <= 1 + 1e-9


def test_a_1e308_spectrum_is_normalised_without_overflow(tmp_path):
    """Sums of values near float64's largest overflowed (a RuntimeWarning, then a visible
    share of NaN); an illuminant is divided by its peak first, and only its shape counts."""
    import warnings

    path = tmp_path / "big.csv"
    path.write_text("wavelength [nm],lamp [W/m2/nm]\n380,1e308\n550,1e308\n780,1e308\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a RuntimeWarning fails the test
        big = get_spectrum(f"csv:{path}#lamp [W/m2/nm]")
    unit = tmp_path / "unit.csv"  # another file: spectra are cached by name
    unit.write_text("wavelength [nm],lamp [W/m2/nm]\n380,1\n550,1\n780,1\n")
    expected = get_spectrum(f"csv:{unit}#lamp [W/m2/nm]").values
    assert np.isfinite(big.values).all()
    np.testing.assert_allclose(big.values, expected, rtol=1e-12)


def _glb(path: Path, accessors: list, meshes: list, nodes: list) -> None:
    import json
    import struct

    doc = {"asset": {"version": "2.0"}, "accessors": accessors, "meshes": meshes, "nodes": nodes}
    data = json.dumps(doc).encode()
    data += b" " * (-len(data) % 4)
    chunk = struct.pack("<I4s", len(data), b"JSON") + data
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(chunk)) + chunk)


_COUNTS = st.one_of(st.integers(0, 400_000), st.sampled_from([-1, 2**63, "7", None, 1.5]))


@SETTINGS
@hypothesis.given(
    counts=st.lists(_COUNTS, min_size=1, max_size=4),
    indexed=st.booleans(),
    nodes=st.lists(st.integers(-1, 4), max_size=6),
)
def test_a_glb_within_the_face_budget_loads_only_as_counted_or_is_refused(counts, indexed, nodes):
    """Drawn glTF accessor counts and node lists: the counts are whole and non-negative, and
    the budget refuses exactly the files whose counted faces or vertices pass its limits,
    before trimesh reads any geometry (here there is none to read)."""
    from spectrinsic.scenes.budget import MAX_FACES, MAX_VERTICES, SceneBudget
    from spectrinsic.scenes.mesh_counts import check_mesh_size, mesh_counts

    accessors = [{"count": c} for c in counts]
    primitive = {"attributes": {"POSITION": 0}} | ({"indices": len(counts) - 1} if indexed else {})
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "drawn.glb"
        _glb(path, accessors, [{"primitives": [primitive]}], [{"mesh": n} for n in nodes])
        n_v, n_f = mesh_counts(path)
        assert isinstance(n_v, int) and isinstance(n_f, int) and n_v >= 0 and n_f >= 0
        try:
            check_mesh_size(path, SceneBudget("drawn.glb"))
        except Exception as exc:  # noqa: BLE001 - the property is about which exceptions escape
            _refused_in_one_line(exc)
            assert n_f > MAX_FACES or n_v > MAX_VERTICES
            return
    assert n_f <= MAX_FACES and n_v <= MAX_VERTICES
