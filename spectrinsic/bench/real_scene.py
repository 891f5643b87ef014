"""Benchmark of reading an artist-sized Mitsuba XML interior (issue 41): spectrinsic's reader
against Mitsuba's own ``load_file`` of the same file, time and peak memory.

A synthetic interior is written to a temporary folder: :data:`MESHES` OBJ meshes (subdivided
boxes of :data:`FACES_PER_MESH` triangles, laid out on a grid in a room), :data:`MATERIALS`
diffuse and rough-plastic BSDFs referenced by id, a ceiling area light, a point light and a
perspective sensor. (Bitmap textures, which the issue's interior also has, are refused until
issue 41's texture route lands, so they are left out here.)

Each reader runs in a fresh process (``spawn``) so that its peak resident memory
(``ru_maxrss``) is its own: ``load_mitsuba_xml`` (checks, Mitsuba's parser, the budget, every
mesh read, validation) and ``mitsuba.load_file`` (``scalar_rgb``: every plugin instantiated).
Seconds are the median of :data:`REPEATS` loads in that process after a first, untimed one;
memory is the process's peak less its resident size after the imports. Goals of issue 41: at
most 2 × Mitsuba's time and 2 GB.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import resource
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..file_writes import write_text_file
from ..render.base.variants import import_mitsuba
from ..scenes.mitsuba_xml import load_mitsuba_xml

MESHES = 300
#: Triangles of each mesh: a box whose faces are split into a 6 x 6 grid of quads (432).
GRID = 6
FACES_PER_MESH = 6 * GRID * GRID * 2
MATERIALS = 20
REPEATS = 3
TIME_GOAL = 2.0
MEMORY_GOAL_BYTES = 2 * 1024**3


def box_obj(grid: int, *, uv: bool = False) -> str:
    """An OBJ box [-1, 1]³ with each face split into *grid* × *grid* quads (two triangles each);
    with *uv*, each box face spans the texture's unit square (``vt``, one per vertex)."""
    lines: list[str] = []
    texcoords: list[str] = []
    faces: list[str] = []
    t = np.linspace(-1.0, 1.0, grid + 1)
    for axis in range(3):
        for sign in (-1.0, 1.0):
            base = len(lines)
            for a in t:
                for b in t:
                    p = np.empty(3)
                    p[axis], p[(axis + 1) % 3], p[(axis + 2) % 3] = sign, a, b
                    lines.append("v {:.6g} {:.6g} {:.6g}".format(*p))
                    texcoords.append(f"vt {(a + 1) / 2:.6g} {(b + 1) / 2:.6g}")
            for i in range(grid):
                for j in range(grid):
                    v00 = base + i * (grid + 1) + j + 1
                    v01, v10, v11 = v00 + 1, v00 + grid + 1, v00 + grid + 2
                    quad = (v00, v10, v11, v01) if sign > 0 else (v00, v01, v11, v10)
                    q = [f"{v}/{v}" if uv else str(v) for v in quad]
                    faces.append(f"f {q[0]} {q[1]} {q[2]}")
                    faces.append(f"f {q[0]} {q[2]} {q[3]}")
    return "\n".join(lines + (texcoords if uv else []) + faces) + "\n"


def plain_bsdf(bsdf_id: str, rough: bool, rng: np.random.Generator) -> str:
    """A material of one random colour (three draws of *rng*): a GGX ``roughplastic`` if
    *rough*, else a two-sided ``diffuse``."""
    r, g, b = rng.uniform(0.1, 0.8, 3)
    rgb = f'<rgb name="{{}}" value="{r:.3f}, {g:.3f}, {b:.3f}"/>'
    if rough:
        return (
            f'<bsdf type="roughplastic" id="{bsdf_id}">{rgb.format("diffuse_reflectance")}'
            '<float name="alpha" value="0.2"/><string name="distribution" value="ggx"/></bsdf>'
        )
    return (
        f'<bsdf type="twosided" id="{bsdf_id}"><bsdf type="diffuse">'
        f"{rgb.format('reflectance')}</bsdf></bsdf>"
    )


def write_interior(folder: Path, meshes: int | None = None) -> Path:
    """The synthetic interior (module docstring) in *folder*, of *meshes* meshes (default
    :data:`MESHES`); the scene file's path."""
    meshes = MESHES if meshes is None else meshes
    (folder / "meshes").mkdir(parents=True, exist_ok=True)
    box = box_obj(GRID)
    rng = np.random.default_rng(41)
    parts = [
        '<scene version="3.0.0">',
        '<integrator type="path"><integer name="max_depth" value="6"/></integrator>',
    ]
    parts += [plain_bsdf(f"m{m}", m % 4 == 3, rng) for m in range(MATERIALS)]
    side = int(np.ceil(np.sqrt(meshes)))
    for i in range(meshes):
        write_text_file(folder / "meshes" / f"obj{i:03d}.obj", box)
        x, y = (i % side) / side * 8 - 4, (i // side) / side * 8 - 4
        parts.append(
            f'<shape type="obj" id="obj{i:03d}"><string name="filename" value="meshes/obj{i:03d}.obj"/>'
            f'<ref id="m{i % MATERIALS}"/><transform name="to_world"><scale value="0.1"/>'
            f'<translate x="{x:.4f}" y="{y:.4f}" z="0.1"/></transform></shape>'
        )
    parts += [
        '<shape type="rectangle" id="floor"><ref id="m0"/><transform name="to_world"><scale value="5"/></transform></shape>',
        '<shape type="rectangle" id="lamp"><transform name="to_world"><scale value="0.5"/>'
        '<rotate x="1" angle="180"/><translate z="2.9"/></transform>'
        '<emitter type="area"><rgb name="radiance" value="4"/></emitter></shape>',
        '<emitter type="point"><point name="position" x="1" y="1" z="2"/><rgb name="intensity" value="3"/></emitter>',
        '<sensor type="perspective"><float name="fov" value="60"/><transform name="to_world">'
        '<lookat origin="0, -6, 2.5" target="0, 0, 0" up="0, 0, 1"/></transform>'
        '<sampler type="independent"><integer name="sample_count" value="16"/></sampler>'
        '<film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="48"/></film></sensor>',
        "</scene>",
    ]
    path = folder / "interior.xml"
    write_text_file(path, "\n".join(parts))
    return path


def _rss_bytes() -> int:
    """This process's peak resident size (``ru_maxrss``: KiB on Linux, bytes on macOS)."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return int(peak if sys.platform == "darwin" else peak * 1024)


def _measure(reader: str, path: str) -> dict[str, Any]:
    """Load *path* with *reader* in this (fresh) process: median seconds and peak memory."""
    if reader == "spectrinsic":

        def load() -> Any:
            return load_mitsuba_xml(path)
    else:
        mi = import_mitsuba()
        mi.set_variant("scalar_rgb")

        def load() -> Any:
            return mi.load_file(path)

    baseline = _rss_bytes()
    load()  # untimed: first-use costs (plugin registry, caches)
    seconds = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        load()
        seconds.append(time.perf_counter() - start)
    return {"seconds": float(np.median(seconds)), "peak_bytes": _rss_bytes() - baseline}


def _in_fresh_process(reader: str, path: Path) -> dict[str, Any]:
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=context) as pool:
        return pool.submit(_measure, reader, str(path)).result()


def run(out_dir: Path) -> dict[str, Any]:
    with tempfile.TemporaryDirectory(dir=out_dir) as tmp:
        path = write_interior(Path(tmp))
        ours = _in_fresh_process("spectrinsic", path)
        theirs = _in_fresh_process("mitsuba", path)
    faces = MESHES * FACES_PER_MESH + 2  # the floor's two triangles
    ratio = ours["seconds"] / theirs["seconds"]
    return {
        "scene": f"{MESHES} OBJ meshes x {FACES_PER_MESH} faces, {MATERIALS} materials, 2 lights",
        "faces": faces,
        "spectrinsic_seconds": ours["seconds"],
        "mitsuba_load_file_seconds": theirs["seconds"],
        "time_ratio": ratio,
        "time_goal": TIME_GOAL,
        "spectrinsic_peak_bytes": ours["peak_bytes"],
        "mitsuba_peak_bytes": theirs["peak_bytes"],
        "spectrinsic_peak_bytes_per_100k_faces": ours["peak_bytes"] * 1e5 / faces,
        "memory_goal_bytes": MEMORY_GOAL_BYTES,
        "met": ratio <= TIME_GOAL and ours["peak_bytes"] <= MEMORY_GOAL_BYTES,
    }
