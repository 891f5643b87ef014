"""Byte-identity check of the rendering outputs: build small samples of every kind, hash every file.

Usage: ``python scripts/byte_identity.py OUT.json [--keep DIR]``, run with the interpreter of the
environment whose code is checked (its ``spectrinsic`` command beside it). Needs the spectral data
(``SPECTRINSIC_DATA``, default ``/work/shared/data``).

It builds, in a temporary folder: a matte library sample (single traversal), the same sample
at 12 and 6 spp (both renders split into parts), the same with ``--integrator passes``, a glossy (plastics and metals) and a textured generated room, a gold-room scene file
(metals, plastic, a textured material), a floor under a coloured environment map and a
sphere light (an XML scene) at 12 and 6 spp, a sample with ``--store-transport`` plus a sample
relit from it by ``spectrinsic relight``, an ``evaluate`` run on the matte dataset, and the two
spectral studies. It writes ``{relative path: sha256}`` of every output file to OUT.json:
``scene.json`` is left out (its texel weights follow the scene hash since issue 35), and
JSON files (``meta.json``, ``manifest.json``, the studies') are hashed as canonical JSON without
version strings, the git commit and ``config_hash``, and without the hashes of ``scene.json`` and ``meta.json`` they list (so a
version bump alone does not count as a change). Build times change from run to run and are left
out: a dataset's ``build-time.json`` is hashed without its fields ``finished``, ``wall_seconds``,
``sample_seconds``, ``mitsuba_seconds`` and ``cpus`` (each run's ``samples_built`` is kept), and
``DATASET.md`` without its one line that starts with ``Build time:`` (time, CPUs, dates); the
card's size figures stay in, as they follow the sample files' bytes. Compare two runs with
``python scripts/byte_identity.py --compare A.json B.json``; re-hash a folder kept with
``--keep DIR`` by ``--hash DIR OUT.json``.
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

GOLD_ROOM = """\
format: 1
name: gold-room
materials:
  wall: "munsell:5Y 7/4"
  floor: "flat:0.5"
  gold: {kind: conductor, metal: Au, roughness: 0.1}
  glaze: {kind: plastic, spectrum: "munsell:5B 5/8", ior: 1.5, roughness: 0.05}
  wood: {kind: textured, basis: ["munsell:10YR 6/6", "munsell:5YR 5/4"], pattern: rings, size: 16, seed: 3}
meshes:
  - name: floor
    vertices: [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]
    faces: [[0, 1, 2], [0, 2, 3]]
    material: floor
  - name: back
    vertices: [[-2, 2, 0], [2, 2, 0], [2, 2, 2], [-2, 2, 2]]
    faces: [[0, 1, 2], [0, 2, 3]]
    material: wall
  - name: mirror
    vertices: [[-1, 1, 0.01], [0, 1, 0.01], [0, 1, 1], [-1, 1, 1]]
    faces: [[0, 1, 2], [0, 2, 3]]
    material: gold
  - name: tile
    vertices: [[0.2, -0.5, 0.01], [1, -0.5, 0.01], [1, 0.3, 0.01], [0.2, 0.3, 0.01]]
    faces: [[0, 1, 2], [0, 2, 3]]
    material: glaze
  - name: board
    vertices: [[-1, -1, 0.02], [-0.2, -1, 0.02], [-0.2, -0.2, 0.02], [-1, -0.2, 0.02]]
    faces: [[0, 1, 2], [0, 2, 3]]
    material: wood
lights:
  - kind: point
    spectrum: "planck:2800K"
    power: 8.0
    position: [1, -1, 1.8]
  - kind: point
    spectrum: "cie:D65"
    power: 4.0
    position: [-1, -1.5, 1.5]
camera:
  origin: [0.3, -2.5, 1.4]
  target: [0, 0.5, 0.4]
  width: 24
  height: 24
"""

#: Keys removed before hashing meta.json / manifest.json.
_DROPPED = {
    "config_hash",
    "version",
    "versions",
    "spectrinsic_version",
    "git_commit",
    "git_sha",
    "created",
}
#: Keys removed before hashing a dataset's ``build-time.json`` (its run-dependent fields,
#: ``build_time.RUN_TIME_FIELDS``; the count of samples each run built is kept).
_BUILD_TIME_FIELDS = {"finished", "wall_seconds", "sample_seconds", "mitsuba_seconds", "cpus"}
#: The dataset card's one line of build time, machine and date (``build_time.BUILD_TIME_LINE``).
_CARD_TIME_LINE = "Build time:"
_FAST = ["--preset", "preview", "--resolution", "24x24", "--spp", "4", "--spectral-spp", "2"]
#: Counts that split both renders into parts (12 = 8 + 4, 6 = 4 + 2;
#: ``render/base/sample_split.py``): the route of the default preset's 320 and 64 spp.
_SPLIT = ["--preset", "preview", "--resolution", "24x24", "--spp", "12", "--spectral-spp", "6"]
#: A floor under a coloured environment map (its spectral reference is one summed pass,
#: ``render/base/summed_envmap.py``) beside a sphere light.
SKY_ROOM = """<scene version="3.0.0">
  <emitter type="envmap">
    <string name="filename" value="sky.exr"/>
    <float name="scale" value="2"/>
    <transform name="to_world"><rotate x="1" angle="90"/></transform>
  </emitter>
  <shape type="rectangle">
    <transform name="to_world"><scale value="5"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.6, 0.3"/></bsdf>
  </shape>
  <shape type="sphere">
    <point name="center" x="0.5" y="0" z="0.6"/><float name="radius" value="0.2"/>
    <emitter type="area"><rgb name="radiance" value="3, 3, 2"/></emitter>
  </shape>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,-3,2" target="0,0,0" up="0,0,1"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film>
  </sensor>
</scene>
"""


def _write_sky(folder: Path) -> Path:
    """SKY_ROOM and its 16 x 8 map (a blue zenith over a warm horizon, by rows) in *folder*."""
    import numpy as np

    from spectrinsic.mitsuba_import import import_mitsuba

    mi = import_mitsuba()
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    rows = np.linspace(0.0, 1.0, 8, dtype=np.float32)[:, None, None]
    sky = (1 - rows) * np.array([0.3, 0.5, 1.0], np.float32) + rows * np.array([1.0, 0.7, 0.4])
    mi.Bitmap(np.ascontiguousarray(np.repeat(sky, 16, axis=1), np.float32)).write(
        str(folder / "sky.exr")
    )
    (folder / "sky-room.xml").write_text(SKY_ROOM)
    return folder / "sky-room.xml"


def _strip(value: object) -> object:
    if isinstance(value, dict):
        return {
            k: _strip(v)
            for k, v in value.items()
            if k not in _DROPPED
            and not k.endswith(("_version", "_sha256", "scene.json", "meta.json"))
        }
    if isinstance(value, list):
        return [_strip(v) for v in value]
    return value


def _digest(path: Path) -> str:
    if path.name == "build-time.json":
        runs = json.loads(path.read_text())["runs"]
        kept = [{k: v for k, v in run.items() if k not in _BUILD_TIME_FIELDS} for run in runs]
        return hashlib.sha256(json.dumps(kept, sort_keys=True).encode()).hexdigest()
    if path.name == "DATASET.md":
        lines = path.read_text(encoding="utf-8").splitlines(keepends=True)
        kept_text = "".join(x for x in lines if not x.startswith(_CARD_TIME_LINE))
        return hashlib.sha256(kept_text.encode()).hexdigest()
    if path.suffix == ".json":
        data = _strip(json.loads(path.read_text()))
        return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _run(exe: Path, *args: str) -> None:
    t0 = time.perf_counter()
    subprocess.run(
        [str(exe), *args], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    print(f"{time.perf_counter() - t0:6.1f} s  {' '.join(args[:4])}", file=sys.stderr)


def build(root: Path) -> None:
    """Every output of the check under *root*."""
    exe = Path(sys.executable).with_name("spectrinsic")
    only = ["--only", "obj-apple__v0__two-colour-a"]
    _run(exe, "dataset", "--out", str(root / "matte"), *_FAST, *only)
    _run(exe, "dataset", "--out", str(root / "split"), *_SPLIT, *only)
    _run(exe, "dataset", "--out", str(root / "passes"), *_FAST, *only, "--integrator", "passes")
    gen = ["--generator", "rooms", "--count", "1", "--views", "1"]
    gloss = ["--glossy", "0.5", "--metallic", "0.3"]
    _run(exe, "dataset", "--out", str(root / "glossy"), *_FAST, *gen, *gloss)
    _run(exe, "dataset", "--out", str(root / "textured"), *_FAST, *gen, "--texture-fraction", "1")
    # a fixed path: the scene file's path is part of the dataset config (and its hash)
    scene_file = Path(tempfile.gettempdir()) / "spectrinsic-byte-identity" / "gold-room.yaml"
    scene_file.parent.mkdir(exist_ok=True)
    scene_file.write_text(GOLD_ROOM)
    _run(exe, "dataset", "--out", str(root / "gold"), *_FAST, "--scenes", str(scene_file))
    sky_file = _write_sky(scene_file.parent)
    _run(exe, "dataset", "--out", str(root / "sky"), *_SPLIT, "--scenes", str(sky_file))
    store = root / "store"
    _run(
        exe,
        "dataset",
        "--out",
        str(store),
        *_FAST,
        "--scenes",
        str(scene_file),
        "--store-transport",
    )
    sample = next(p.parent for p in sorted(store.glob("*/transport.exr")))
    light = ["--light", "0=daylight:5000K", "--light", "1=cie:FL11"]
    _run(exe, "relight", str(sample), *light, "--out", str(root / "relit"))
    _run(exe, "evaluate", "--dataset", str(root / "matte"), "--out", str(root / "eval"))
    _run(exe, "study", "reconstruction-error", "--no-extension", "--out", str(root / "studies"))
    _run(exe, "study", "photometric", "--out", str(root / "studies"))


def hashes(root: Path) -> dict[str, str]:
    return {
        str(p.relative_to(root)): _digest(p)
        for p in sorted(root.rglob("*"))
        if p.is_file() and p.name != "scene.json" and ".lock" not in p.name
    }


def compare(a: dict[str, str], b: dict[str, str]) -> dict[str, list[str]]:
    return {
        "equal": [k for k in a if b.get(k) == a[k]],
        "different": [k for k in a if k in b and b[k] != a[k]],
        "only_before": [k for k in a if k not in b],
        "only_after": [k for k in b if k not in a],
    }


def main(argv: list[str]) -> int:
    if argv[:1] == ["--compare"]:
        a, b = (json.loads(Path(p).read_text()) for p in argv[1:3])
        out = compare(a, b)
        print(json.dumps({k: len(v) for k, v in out.items()}))
        for k in ("different", "only_before", "only_after"):
            for name in out[k]:
                print(f"{k}: {name}")
        return 0
    if argv[:1] == ["--hash"]:  # re-hash a folder kept with --keep
        Path(argv[2]).write_text(json.dumps(hashes(Path(argv[1])), indent=1, sort_keys=True) + "\n")
        return 0
    os.environ.setdefault("SPECTRINSIC_DATA", "/work/shared/data")
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    with tempfile.TemporaryDirectory(prefix="byte-identity-") as tmp:
        root = Path(argv[2]) if argv[1:2] == ["--keep"] else Path(tmp)
        build(root)
        table = hashes(root)
    Path(argv[0]).write_text(json.dumps(table, indent=1, sort_keys=True) + "\n")
    print(f"{len(table)} files -> {argv[0]}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
