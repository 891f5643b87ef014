"""Every bad input of issue 9 through the command line: exit status 2, one line on stderr that
names the input, no traceback, and no user file touched (nor any output left behind).

Each case builds its input under ``tmp_path``, next to a few files standing for the user's own
data; the whole tree is snapshotted (paths, bytes, mtimes) before and compared after the run.
None of these cases renders: every refusal comes before the first pass.
"""

from __future__ import annotations

import importlib.util
import json
import socket
from collections.abc import Callable
from pathlib import Path

import pytest

from spectrinsic.cli import main
from spectrinsic.errors import DatasetError
from spectrinsic.gt_export.folders.build_folder import MARKER_NAME, write_marker
from spectrinsic.pipeline.presets import get_preset
from tests.conftest import QUAD_YAML, TINY_BUILD

APPLE = "obj-apple__v0__white"
#: The tiny build of one library sample.
TINY = [*TINY_BUILD, "--only", APPLE]
TINY_HASH = get_preset("preview").with_options(width=16, height=16, spp=2).config_hash()


#: A scene whose second mesh has only a zero-area face (three collinear vertices).
SLIVER = QUAD_YAML.replace(
    "lights:",
    """  - name: sliver
    vertices: [[0, 0, 0.5], [1, 0, 0.5], [2, 0, 0.5]]
    faces: [[0, 1, 2]]
    material: grey
lights:""",
)
#: A PLY mesh whose only face has zero area.
FLAT_PLY = (
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n"
)
#: The manifest of a finished dataset, as far as recognising one goes.
BUILT = {"format_version": 1, "config_hash": "h"}
#: A one-triangle OBJ without a material map.
TRIANGLE_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


def _own_output(tmp: Path, extra: str, killed: bool = False) -> str:
    """An output folder spectrinsic wrote (its marker lists ``a.json``) holding *extra* too;
    *killed*: the marker says a run was writing when it died."""
    from spectrinsic.gt_export.folders.outfolder import OUTPUT_MARKER

    out = tmp / "results"
    out.mkdir()
    (out / "a.json").write_text("{}")
    (out / extra).write_text("mine")
    writing = {"pid": 1, "host": "h", "started": "then"} if killed else None
    (out / OUTPUT_MARKER).write_text(
        json.dumps({"spectrinsic_output": 1, "files": ["a.json"], "writing": writing})
    )
    return str(out)


def _snapshot(root: Path) -> dict[str, tuple[bytes, int]]:
    return {
        p.relative_to(root).as_posix(): (p.read_bytes(), p.stat().st_mtime_ns)
        for p in sorted(root.rglob("*"))
        if p.is_file()
    } | {p.relative_to(root).as_posix() + "/": (b"", 0) for p in root.rglob("*") if p.is_dir()}


def _user_files(tmp: Path) -> None:
    """Files standing for the user's own data, which no run may touch."""
    (tmp / "thesis").mkdir()
    (tmp / "thesis" / "thesis.tex").write_text("\\chapter{Intro}\n")
    (tmp / ".tmp-mine").mkdir()
    (tmp / ".tmp-mine" / "db").write_text("b")


def _closed_port() -> int:
    """A TCP port on 127.0.0.1 with nothing listening (bound, then released)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _sfu_data_dir(tmp: Path, value: str, encoding: str = "utf-8") -> Path:
    """A data directory whose SFU reflectance file holds *value* for spectrum 1 at 500 nm."""
    folder = tmp / "data" / "sfu_barnard2002"
    folder.mkdir(parents=True)
    rows = [f"{wl},{value if wl == 500 else 0.5},0.4" for wl in range(380, 790, 10)]
    text = "wavelength_nm,s1,s2\n" + "\n".join(rows) + "\n"
    (folder / "reflect_db_1995.csv").write_bytes(text.encode(encoding))
    (folder / "reflect_db_index.csv").write_text(
        "column_1based,label,group,index_in_group\n1,s1,mine,1\n2,s2,mine,2\n"
    )
    return tmp / "data"


def _sfu_render(tmp: Path, value: str | None, encoding: str = "utf-8") -> list[str]:
    """``render`` of a scene using an SFU reflectance from a data directory holding *value*
    (``None``: a data directory that does not exist)."""
    data = _sfu_data_dir(tmp, value, encoding) if value is not None else tmp / "nope"
    scene = _scene(tmp, QUAD_YAML.replace("flat:0.5", "sfu:mine/1"))
    return ["--data-dir", str(data), "render", scene, "--out", str(tmp / "o")]


def _scene(tmp: Path, text: str = QUAD_YAML, name: str = "scene.yaml") -> str:
    path = tmp / name
    path.write_text(text) if isinstance(text, str) else path.write_bytes(text)
    return str(path)


def _fake_sample(root: Path, name: str, extra: str | None = None) -> None:
    """A sample folder with a spectrinsic-shaped meta.json (another config), and maybe a
    user's file in it."""
    folder = root / name
    folder.mkdir(parents=True)
    (folder / "meta.json").write_text(
        json.dumps({"format_version": 1, "sample_id": name, "config_hash": "old", "files": []})
    )
    if extra:
        (folder / extra).write_text("mine")


def _dataset_with(tmp: Path, setup: Callable[[Path], None], config_hash: str = TINY_HASH) -> str:
    root = tmp / "ds"
    write_marker(root, config_hash)
    setup(root)
    return str(root)


def _built_like(tmp: Path, manifest: object | None = None, meta: dict | None = None) -> str:
    """A dataset folder holding one sample whose meta.json is *meta*, and *manifest*."""
    root = tmp / "ds"
    (root / APPLE).mkdir(parents=True)
    base = {
        "format_version": 3,
        "sample_id": APPLE,
        "config_hash": "h",
        "files": [],
        "sha256": {},
        "layers": {},
        "scene": "obj-apple",
        "scene_hash": "0",
        "scene_metadata": {},
        "seed": 1,
        "variants": [],
        "render": {},
        "reference_mode": "spectral",
        "size": [16, 16],
        "spectral_grid": {},
        "materials": {},
        "objects": {},
        "lights": [],
        "cameras": [],
        "cube_sensors": None,
        "matrices": {},
        "identities": [],
        "denoised_layers": [],
        "noise": {},
        "shading_clipping": {},
        "versions": {},
        "meta_sha256": "0" * 64,
    }
    (root / APPLE / "meta.json").write_text(json.dumps({**base, **(meta or {})}))
    if manifest is not None:
        (root / "manifest.json").write_text(json.dumps(manifest))
    return str(root)


def _bomb(tmp: Path) -> str:
    """A 1.2 KB "billion laughs": 10 levels of 9 aliases each."""
    lines = ["l0: &l0 [" + ", ".join(["lol" * 16] * 9) + "]"]
    lines += [f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 9) + "]" for i in range(1, 11)]
    text = "\n".join(lines) + "\n"
    assert 1000 < len(text) < 1300
    return _scene(tmp, text)


#: (case id, builder of argv from tmp_path, text the one stderr line must contain)
CASES: list[tuple[str, Callable[[Path], list[str]], str]] = [
    # --- point 1: dataset --out never deletes user data
    (
        "out-nonempty-not-dataset",
        lambda t: ["dataset", *TINY, "--out", str(t)],
        "not a spectrinsic dataset",
    ),
    (
        "out-sample-named-folder",
        lambda t: (lambda d: ["dataset", *TINY, "--out", d])(
            _dataset_with(
                t, lambda r: (r / APPLE).mkdir() or (r / APPLE / "thesis.tex").write_text("a")
            )
        ),
        "no valid spectrinsic meta.json",
    ),
    (
        "out-sample-holds-user-file",
        lambda t: [
            "dataset",
            *TINY,
            "--out",
            _dataset_with(t, lambda r: _fake_sample(r, APPLE, "notes.txt")),
        ],
        "notes.txt",
    ),
    (
        "out-sample-name-is-a-file",
        lambda t: [
            "dataset",
            *TINY,
            "--out",
            _dataset_with(t, lambda r: (r / APPLE).write_text("mine")),
        ],
        APPLE,
    ),
    # --- point 3: one config per dataset
    (
        "out-other-config",
        lambda t: [
            "dataset",
            *TINY,
            "--out",
            _dataset_with(t, lambda r: None, config_hash="0" * 64),
        ],
        "--rebuild",
    ),
    # --- point 7: one-line errors
    (
        "out-is-a-file",
        lambda t: ["dataset", *TINY, "--out", str(t / "thesis" / "thesis.tex")],
        "is a file",
    ),
    (
        "out-below-a-file",
        lambda t: ["dataset", *TINY, "--out", str(t / "thesis" / "thesis.tex" / "x")],
        "lies below the file",
    ),
    (
        "render-out-below-a-file",
        lambda t: ["render", "obj-apple", "--out", str(t / "thesis" / "thesis.tex" / "x")],
        "lies below the file",
    ),
    (
        "render-width-negative",
        lambda t: ["render", "obj-apple", "--width", "-5", "--out", str(t / "o")],
        "--width -5",
    ),
    (
        "render-width-zero",
        lambda t: ["render", "obj-apple", "--width", "0", "--out", str(t / "o")],
        "--width 0",
    ),
    (
        "render-width-huge",
        lambda t: ["render", "obj-apple", "--width", "100000", "--out", str(t / "o")],
        "--width 100000",
    ),
    (
        "render-spp-zero",
        lambda t: ["render", "obj-apple", "--spp", "0", "--out", str(t / "o")],
        "--spp 0",
    ),
    (
        "render-unknown-mode",
        lambda t: ["render", "obj-apple", "--modes", "spectral,rgb9", "--out", str(t / "o")],
        "rgb9",
    ),
    (
        "render-unknown-scene",
        lambda t: ["render", "obj-apricot", "--out", str(t / "o")],
        "obj-apricot",
    ),
    (
        "scheduler-closed-port",
        lambda t: [
            "dataset",
            *TINY,
            "--out",
            str(t / "new"),
            "--scheduler",
            f"tcp://127.0.0.1:{_closed_port()}",
        ],
        "127.0.0.1",
    ),
    (
        "scheduler-malformed",
        lambda t: ["dataset", *TINY, "--out", str(t / "new"), "--scheduler", "tcp//nohost"],
        "tcp//nohost",
    ),
    (
        "scheduler-bad-port",
        lambda t: [
            "dataset",
            *TINY,
            "--out",
            str(t / "new"),
            "--scheduler",
            "tcp://127.0.0.1:99999",
        ],
        "99999",
    ),
    (
        "yaml-5000-deep",
        lambda t: ["render", _scene(t, "- " * 5000 + "x\n"), "--out", str(t / "o")],
        "scene.yaml",
    ),
    (
        "yaml-5000-deep-flow",
        lambda t: ["render", _scene(t, "[" * 5000 + "]" * 5000), "--out", str(t / "o")],
        "nesting deeper",
    ),
    (
        "yaml-not-utf8",
        lambda t: ["render", _scene(t, b"name: \xff\xfe\n"), "--out", str(t / "o")],
        "scene.yaml",
    ),
    (
        "data-dir-csv-not-utf8",
        lambda t: _sfu_render(t, "0.5\xe9", "latin-1"),
        "reflect_db_1995.csv",
    ),
    (
        "blend-garbage",
        lambda t: [
            "render",
            _scene(t, b"BLENDER-v300 not really", "room.blend"),
            "--out",
            str(t / "o"),
        ],
        "room.blend",
    ),
    (
        "blend-magic-any-name",
        lambda t: [
            "render",
            _scene(t, b"BLENDER-v300 not really", "room.dat"),
            "--out",
            str(t / "o"),
        ],
        "room.dat",
    ),
    ("check-manifest-list", lambda t: ["check", _built_like(t, manifest=[])], "manifest.json"),
    (
        "check-layer-without-file",
        lambda t: [
            "check",
            _built_like(t, manifest={}, meta={"layers": {"image": {"exr_layer": "image"}}}),
        ],
        "layers.image.file",
    ),
    ("check-not-a-folder", lambda t: ["check", str(t / "nothing")], "nothing"),
    # --- point 5: spectra from the data directory
    ("data-dir-nan", lambda t: _sfu_render(t, "nan"), "reflect_db_1995.csv"),
    ("data-dir-inf", lambda t: _sfu_render(t, "inf"), "reflect_db_1995.csv"),
    ("data-dir-negative", lambda t: _sfu_render(t, "-0.2"), "reflect_db_1995.csv"),
    ("data-dir-above-one", lambda t: _sfu_render(t, "1e30"), "too large value 1e+30"),
    ("data-dir-empty-cell", lambda t: _sfu_render(t, ""), "reflect_db_1995.csv"),
    ("data-dir-missing", lambda t: _sfu_render(t, None), "nope"),
    # --- point 8: limits
    ("yaml-alias-bomb", lambda t: ["render", _bomb(t), "--out", str(t / "o")], "alias"),
    (
        "yaml-recursive-alias",
        lambda t: ["render", _scene(t, "a: &a [*a]\n"), "--out", str(t / "o")],
        "recursive",
    ),
    (
        "yaml-duplicate-key",
        lambda t: ["render", _scene(t, QUAD_YAML + "name: again\n"), "--out", str(t / "o")],
        "duplicate key 'name'",
    ),
    (
        "yaml-too-large",
        lambda t: ["render", _scene(t, "# " + "x" * (17 * 2**20) + "\n"), "--out", str(t / "o")],
        "limited to",
    ),
    (
        "yaml-several-mistakes",
        lambda t: [
            "render",
            _scene(
                t,
                QUAD_YAML.replace("point,", "pointy,")
                .replace("width: 16", "width: -3")
                .replace("material: grey", "material: blue")
                + "colour: 3\n",
            ),
            "--out",
            str(t / "o"),
        ],
        "4 problems",
    ),
    (
        "dataset-resolution-zero",
        lambda t: [
            "dataset",
            "--preset",
            "preview",
            "--resolution",
            "0x16",
            "--out",
            str(t / "new"),
        ],
        "--resolution '0x16'",
    ),
    (
        "dataset-resolution-garbage",
        lambda t: [
            "dataset",
            "--preset",
            "preview",
            "--resolution",
            "big",
            "--out",
            str(t / "new"),
        ],
        "--resolution 'big'",
    ),
    (
        "dataset-workers-zero",
        lambda t: ["dataset", *TINY, "--workers", "0", "--out", str(t / "new")],
        "--workers 0",
    ),
    (
        "dataset-threads-zero",
        lambda t: ["dataset", *TINY, "--threads", "0", "--out", str(t / "new")],
        "--threads 0",
    ),
    (
        "dataset-only-nothing",
        lambda t: [
            "dataset",
            "--preset",
            "preview",
            "--only",
            "obj-apricot*",
            "--out",
            str(t / "new"),
        ],
        "obj-apricot*",
    ),
    # --- point 9: check confines file entries
    (
        "check-meta-file-outside",
        lambda t: [
            "check",
            _built_like(t, manifest={}, meta={"files": ["../../thesis/thesis.tex"]}),
        ],
        "../../thesis/thesis.tex",
    ),
    (
        "check-manifest-file-outside",
        lambda t: [
            "check",
            _built_like(
                t,
                manifest={
                    "config_hash": "h",
                    "samples": {APPLE: {"files": {"thesis/thesis.tex": "0"}}},
                },
            ),
        ],
        "thesis/thesis.tex",
    ),
    # --- issue 17, item 3: every writing verb follows dataset's --out rule
    (
        "render-out-user-folder",
        lambda t: ["render", "obj-apple", "--out", str(t / "thesis")],
        "not a spectrinsic output folder",
    ),
    (
        "render-out-sample-folder",
        lambda t: ["render", "obj-apple", "--out", str(Path(_built_like(t, BUILT)) / APPLE)],
        "lies inside the dataset folder",
    ),
    (
        "render-out-new-folder-in-dataset",
        lambda t: [
            "render",
            "obj-apple",
            "--out",
            str(Path(_dataset_with(t, lambda r: None)) / "renders"),
        ],
        "lies inside the dataset folder",
    ),
    (
        "evaluate-out-user-folder",
        lambda t: [
            "evaluate",
            "--dataset",
            _built_like(t, manifest={}),
            "--out",
            str(t / "thesis"),
        ],
        "not a spectrinsic output folder",
    ),
    (
        "study-out-user-folder",
        lambda t: ["study", "reconstruction-error", "--out", str(t / "thesis")],
        "not a spectrinsic output folder",
    ),
    (
        "study-out-own-folder-with-user-file",
        lambda t: ["study", "photometric", "--out", _own_output(t, "notes.txt")],
        "'notes.txt'",
    ),
    (
        "study-out-killed-run",
        lambda t: ["study", "photometric", "--out", _own_output(t, "photometric.csv", True)],
        "killed",
    ),
    (
        "export-out-dataset-itself",
        lambda t: (lambda d: ["export", d, "--out", d])(_built_like(t, manifest={})),
        "not an earlier shard export",
    ),
    # --- item 9: a read-only --out is refused before the work (/proc refuses even root's writes)
    (
        "render-out-read-only",
        lambda t: ["render", "obj-apple", "--out", "/proc/spectrinsic-out"],
        "not writable",
    ),
    (
        "evaluate-out-read-only",
        lambda t: [
            "evaluate",
            "--dataset",
            _built_like(t, manifest={}),
            "--out",
            "/proc/spectrinsic-out",
        ],
        "not writable",
    ),
    (
        "study-out-read-only",
        lambda t: ["study", "reconstruction-error", "--out", "/proc/spectrinsic-out"],
        "not writable",
    ),
    (
        "dataset-out-read-only",
        lambda t: ["dataset", *TINY, "--out", "/proc/spectrinsic-out"],
        "not writable",
    ),
    # --- item 11: export --out inside a sample folder of the source
    (
        "export-out-in-sample-folder",
        lambda t: (lambda d: ["export", d, "--out", str(Path(d) / APPLE / "shards")])(
            _built_like(t, BUILT)
        ),
        "lies inside the dataset folder",
    ),
    # --- item 6: no tracebacks
    (
        "render-seed-negative",
        lambda t: ["render", _scene(t), "--seed", "-1", "--out", str(t / "o")],
        "--seed -1",
    ),
    (
        "render-seed-2-32",
        lambda t: ["render", _scene(t), "--seed", "4294967296", "--out", str(t / "o")],
        "--seed 4294967296",
    ),
    (
        "render-spp-2-32",
        lambda t: ["render", _scene(t), "--spp", "4294967296", "--out", str(t / "o")],
        "--spp 4294967296",
    ),
    (
        "dataset-spp-2-32",
        lambda t: ["dataset", *TINY, "--spp", "4294967296", "--out", str(t / "new")],
        "--spp 4294967296",
    ),
    (
        "yaml-zero-area-mesh",
        lambda t: ["render", _scene(t, SLIVER), "--out", str(t / "o")],
        "zero area",
    ),
    (
        "ply-zero-area-mesh",
        lambda t: [
            "render",
            _scene(t, FLAT_PLY, "flat.ply"),
            "--material-map",
            _scene(t, 'flat.ply: "flat:0.5"\n', "map.yaml"),
            "--out",
            str(t / "o"),
        ],
        "zero area",
    ),
    # --- item 9: input errors before any folder is stamped or any render starts
    (
        "dataset-scenes-bad-file",
        lambda t: [
            "dataset",
            "--preset",
            "preview",
            "--scenes",
            _scene(t, QUAD_YAML.replace("flat:0.5", "flat:7")),
            "--out",
            str(t / "new"),
        ],
        "scene.yaml",
    ),
    (
        "dataset-scenes-bad-default-spectrum",
        lambda t: [
            "dataset",
            "--preset",
            "preview",
            "--scenes",
            _scene(t, TRIANGLE_OBJ, "tri.obj"),  # the option applies to mesh files
            "--default-spectrum",
            "munsell:nope",
            "--out",
            str(t / "new"),
        ],
        "--default-spectrum 'munsell:nope'",
    ),
    (
        "dataset-scenes-bad-material-map",
        lambda t: [
            "dataset",
            "--preset",
            "preview",
            "--scenes",
            _scene(t, TRIANGLE_OBJ, "tri.obj"),  # the option applies to mesh files
            "--material-map",
            _scene(t, "grey: nope:1\n", "map.yaml"),
            "--out",
            str(t / "new"),
        ],
        "--material-map entry 'grey'",
    ),
    (
        "dataset-scenes-unmapped-mesh",
        lambda t: [
            "dataset",
            "--preset",
            "preview",
            "--scenes",
            _scene(t, TRIANGLE_OBJ, "tri.obj"),
            "--out",
            str(t / "new"),
        ],
        "not in the material map",
    ),
    (
        "render-ground-truth-bad-file",
        lambda t: [
            "render",
            _scene(t, QUAD_YAML.replace("flat:0.5", "flat:7")),
            "--ground-truth",
            "--out",
            str(t / "new"),
        ],
        "scene.yaml",
    ),
    (
        "data-dir-nonexistent-dataset",
        lambda t: ["--data-dir", str(t / "nope"), "dataset", *TINY, "--out", str(t / "new")],
        "does not exist",
    ),
    (
        "render-max-depth-zero",
        lambda t: ["render", "obj-apple", "--max-depth", "0", "--out", str(t / "o")],
        "--max-depth 0",
    ),
    # checked before the scene is even read (this scene file is bad too)
    (
        "render-variant-bogus",
        lambda t: [
            "render",
            _scene(t, QUAD_YAML.replace("flat:0.5", "flat:7")),
            "--variant",
            "bogus",
            "--out",
            str(t / "o"),
        ],
        "bogus",
    ),
    # --- item 10: unvalidated options
    (
        "check-noise-threshold-nan",
        lambda t: ["check", _built_like(t, manifest={}), "--noise-threshold", "nan"],
        "--noise-threshold nan",
    ),
    (
        "check-noise-threshold-negative",
        lambda t: ["check", _built_like(t, manifest={}), "--noise-threshold", "-1"],
        "--noise-threshold -1",
    ),
    (
        "check-max-per-sample-negative",
        lambda t: ["check", _built_like(t, manifest={}), "--max-per-sample", "-1"],
        "--max-per-sample -1",
    ),
    (
        "study-include-ie-without-cameras",
        lambda t: [
            "--data-dir",
            str(t / "thesis"),
            "study",
            "photometric",
            "--include-ie",
            "--out",
            str(t / "new"),
        ],
        "--include-ie",
    ),
    # --- item 7: bounded inputs
    (
        "dataset-count-huge",
        lambda t: [
            "dataset",
            "--generator",
            "rooms",
            "--count",
            "100000000",
            "--out",
            str(t / "new"),
        ],
        "--count 100000000",
    ),
    (
        "dataset-chroma-range-impossible",
        lambda t: [
            "dataset",
            "--generator",
            "objects-on-ground",
            "--chroma-range",
            "50,60",
            "--out",
            str(t / "new"),
        ],
        "chroma in 50-60",
    ),
    (
        "dataset-light-saturation-impossible",
        lambda t: [
            "dataset",
            "--generator",
            "rooms",
            "--light-saturation",
            "0.4,0.5",
            "--out",
            str(t / "new"),
        ],
        "--light-saturation",
    ),
    (
        "ply-million-vertices",
        lambda t: [
            "render",
            _scene(t, _ply_header(10**6, 1), "big.ply"),
            "--material-map",
            _scene(t, 'big.ply: "flat:0.5"\n', "map.yaml"),
            "--out",
            str(t / "o"),
        ],
        "1,000,000 vertices",
    ),
    (
        "obj-too-many-faces",
        lambda t: [
            "dataset",
            "--preset",
            "preview",
            "--scenes",
            _scene(t, "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + "f 1 2 3\n" * 1_000_001, "many.obj"),
            "--default-spectrum",
            "flat:0.5",
            "--out",
            str(t / "new"),
        ],
        "1,000,001 faces",
    ),
]


def _ply_header(vertices: int, faces: int) -> str:
    """A binary PLY header declaring *vertices* and *faces*, with no data after it."""
    return (
        f"ply\nformat binary_little_endian 1.0\nelement vertex {vertices}\nproperty float x\n"
        f"property float y\nproperty float z\nelement face {faces}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )


#: Cases read by bpy: without the optional 'blender' extra the error is that bpy is missing.
NEEDS_BPY = {"blend-garbage", "blend-magic-any-name"}
_NO_BPY = pytest.mark.skipif(
    importlib.util.find_spec("bpy") is None,
    reason="the optional 'blender' extra (bpy) is not installed: a .blend is not read at all",
)


@pytest.mark.parametrize(
    "build_argv, expected",
    [pytest.param(*c[1:], id=c[0], marks=[_NO_BPY] if c[0] in NEEDS_BPY else []) for c in CASES],
)
def test_bad_input_is_one_line_rc2_and_touches_nothing(tmp_path, capsys, build_argv, expected):
    _user_files(tmp_path)
    argv = build_argv(tmp_path)
    before = _snapshot(tmp_path)
    rc = main(["-q", *argv])
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert rc == 2, captured
    assert len(err.splitlines()) == 1, err
    assert err.startswith("spectrinsic: error: ") and "Traceback" not in err
    assert expected in err, err
    assert _snapshot(tmp_path) == before  # nothing touched, nothing created


def test_render_size_beyond_memory_is_refused_before_rendering(tmp_path, capsys, monkeypatch):
    import spectrinsic.render.budget as budget

    monkeypatch.setattr(budget, "available_memory_bytes", lambda: 2**30)
    rc = main(
        [
            "-q",
            "render",
            "obj-apple",
            "--width",
            "8000",
            "--height",
            "8000",
            "--out",
            str(tmp_path / "o"),
        ]
    )
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1
    assert "--width 8000 --height 8000" in err and "GiB" in err and "1.0 GiB" in err
    assert not (tmp_path / "o").exists()


def test_debug_adds_the_traceback(tmp_path, capsys):
    rc = main(["--debug", "render", "obj-apple", "--width", "-5", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "Traceback" in err and err.strip().endswith("expected a positive integer")


def test_marker_is_what_makes_a_folder_a_dataset(tmp_path):
    write_marker(tmp_path / "ds", TINY_HASH)
    assert json.loads((tmp_path / "ds" / MARKER_NAME).read_text())["config_hash"] == TINY_HASH
    assert [p.name for p in (tmp_path / "ds").iterdir()] == [MARKER_NAME]  # no temporary left


@pytest.mark.parametrize(
    "argv",
    [
        ["render"],
        ["render", "x", "--out", "o", "--seed", "abc"],
        ["bogus"],
        ["check", "d", "--noise-threshold", "high"],
    ],
)
def test_argparse_errors_are_one_line(capsys, argv):
    with pytest.raises(SystemExit) as info:
        main(argv)
    err = capsys.readouterr().err.strip()
    assert info.value.code == 2 and len(err.splitlines()) == 1, err
    assert err.startswith("spectrinsic: error: ") and "usage:" not in err


@pytest.mark.parametrize("compress", ["gzip", "zstd"])
def test_a_compressed_blend_is_known_by_its_magic_under_any_name(tmp_path, compress):
    import gzip

    from spectrinsic.scenes.sources import scene_file_kind

    content = b"BLENDER-v300" + bytes(64)
    if compress == "gzip":
        data = gzip.compress(content)
    else:
        zstandard = pytest.importorskip(
            "zstandard", reason="zstd frames are checked with zstandard"
        )
        data = zstandard.ZstdCompressor().compress(content)
    (tmp_path / "room.dat").write_bytes(data)
    assert scene_file_kind(tmp_path / "room.dat") == "blend"
    (tmp_path / "notes.gz").write_bytes(gzip.compress(b"name: not a blend\n"))
    with pytest.raises(Exception, match="notes.gz"):  # gzip of something else: not a .blend
        scene_file_kind(tmp_path / "notes.gz")


def test_an_exr_whose_channels_attribute_is_not_json_is_one_line(tmp_path, capsys):
    import numpy as np
    import OpenEXR

    from spectrinsic.gt_export.formats.exr import CHANNELS_ATTRIBUTE, read_exr

    path = tmp_path / "reflectance.exr"
    header = {
        "compression": OpenEXR.ZIP_COMPRESSION,
        "type": OpenEXR.scanlineimage,
        CHANNELS_ATTRIBUTE: "{not json",
    }
    OpenEXR.File(header, {"reflectance.R": np.zeros((4, 4), np.float32)}).write(str(path))
    with pytest.raises(DatasetError, match=CHANNELS_ATTRIBUTE):
        read_exr(path)


@pytest.mark.parametrize(
    "text, expected",
    [
        # counted before parsing, from commas and list items: 800 + 400
        (
            "vertices:\n" + "".join(f"  - [{i}, 0, 0]\n" for i in range(400)),
            "about 1,200 YAML values",
        ),
        # block items written "-" + newline escape that count; the composer's count catches them
        ("-\n  1\n" * 1500, "more than 1,000 YAML nodes"),
    ],
)
def test_yaml_node_count_is_bounded_before_and_while_composing(
    tmp_path, monkeypatch, capsys, text, expected
):
    """Issue 17 item 7: a 15 MB YAML under the byte cap took 6 GB and 4.5 min; values are now
    counted before parsing and nodes as the composer builds them (the bound is lowered here so
    the files stay small)."""
    import spectrinsic.scenes.yaml_limits as limits

    monkeypatch.setattr(limits, "MAX_NODES", 1000)
    rc = main(["-q", "render", _scene(tmp_path, text), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and expected in err, err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    "name, text, expected",
    [
        ("a.ply", _ply_header(7, 3), (7, 3)),
        ("a.obj", "# c\nv 0 0 0\nv 1 0 0\nvn 0 0 1\nv 0 1 0\nf 1 2 3\nf 1 3 2\n", (3, 2)),
        ("a.off", "OFF\n# comment\n4 2 0\n", (4, 2)),
        (
            "a.stl",
            "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
            "endloop\nendfacet\nendsolid x\n",
            (3, 1),
        ),
    ],
)
def test_mesh_counts_come_from_the_header_or_a_line_count(tmp_path, name, text, expected):
    from spectrinsic.scenes.mesh_counts import mesh_counts

    (tmp_path / name).write_text(text)
    assert mesh_counts(tmp_path / name) == expected
