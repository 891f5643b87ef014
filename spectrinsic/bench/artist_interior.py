"""Benchmark of an artist's interior rendered with full ground truth (issue 42, "Speed and
memory"): ``render scene.xml --ground-truth`` against Mitsuba's own ``path`` on the same file.

The interior (:func:`write_interior`) is written to a temporary folder: :data:`MESHES` OBJ boxes
of 432 triangles with texture coordinates (:func:`~spectrinsic.bench.real_scene.box_obj`) on a
floor between two walls, :data:`TEXTURES` ``diffuse`` BSDFs over ``bitmap`` textures (16 × 16
PNG checkers, ``nearest``), :data:`PLAIN` diffuse and rough-plastic colours, :data:`GLASS` boxes
of ``dielectric`` glass, a ``conductor`` mirror on the left wall, a ``sunsky`` emitter and a
:data:`WIDTH` × :data:`HEIGHT` sensor at the default preset's spp and depth.

Mitsuba's ``sunsky`` has no exact ground truth: the run reads it with ``--approximate`` (its
sky baked into an RGB map, its sun a directional light: :mod:`~spectrinsic.scenes.mitsuba_sunsky`),
which is what an artist's file with a sun and sky gets.

Each side runs in a fresh process (``spawn``), so its peak resident memory (``ru_maxrss``) is
its own:

* **spectrinsic**: the command line's ``render --ground-truth --approximate`` at the default
  preset, its stages timed where the sample build calls them (:func:`_staged`): load (the XML
  read into a scene), render (every mode, each light's share, the AOVs), ground truth (every
  layer computed) and write (the sample folder: EXR, PNG, meta);
* **Mitsuba**: ``mitsuba.load_file`` and one ``mitsuba.render`` of the file's own ``path``
  integrator, at the preset's ``spp`` and ``max_depth``, in the spectral variant the reference
  pass uses (:func:`~spectrinsic.render.base.variants.choose_variant`) and in the RGB one.

Both include their first-use LLVM compiles (a fresh process, as a user's first render). Goals of
issue 42: at most :data:`TIME_GOAL` × Mitsuba's spectral ``path`` and :data:`MEMORY_GOAL_BYTES`.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import os
import resource
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from ..file_writes import write_text_file
from ..gt_export.formats.png import write_png
from ..gt_export.sample import writer
from ..pipeline import dataset
from ..pipeline.presets import get_preset
from ..pipeline.source_plan import files_source
from ..render.base.variants import choose_variant, import_mitsuba
from .real_scene import GRID, box_obj, plain_bsdf

MESHES = 300
TEXTURES = 20
PLAIN = 20
GLASS = 4
WIDTH, HEIGHT = 700, 400
PRESET = "default"
TIME_GOAL = 3.0
MEMORY_GOAL_BYTES = 4 * 1000**3
#: The sample build's stages, timed by :func:`_staged`.
STAGES = ("load", "render", "ground_truth", "write")
#: The sun's hour (local time, Mitsuba's default place and day): low enough to enter the room.
SUN_HOUR = 15.5


def _texture(path: Path, rng: np.random.Generator) -> None:
    """A 16 × 16 PNG checker of two random sRGB colours."""
    a, b = (rng.integers(30, 230, 3) for _ in range(2))
    checker = (np.indices((16, 16)).sum(axis=0) % 2).astype(bool)
    write_png(path, np.where(checker[..., None], a, b).astype(np.uint8))


def _bsdfs(folder: Path, rng: np.random.Generator) -> list[str]:
    """The textured (``t*``), plain (``m*``), glass and mirror BSDFs, each under an id."""
    (folder / "textures").mkdir(parents=True, exist_ok=True)
    parts = []
    for t in range(TEXTURES):
        _texture(folder / "textures" / f"t{t:02d}.png", rng)
        parts.append(
            f'<bsdf type="twosided" id="t{t}"><bsdf type="diffuse">'
            '<texture type="bitmap" name="reflectance">'
            f'<string name="filename" value="textures/t{t:02d}.png"/>'
            '<string name="filter_type" value="nearest"/></texture></bsdf></bsdf>'
        )
    parts += [plain_bsdf(f"m{m}", m % 4 == 3, rng) for m in range(PLAIN)]
    parts.append('<bsdf type="dielectric" id="glass"><float name="int_ior" value="1.5"/></bsdf>')
    parts.append('<bsdf type="conductor" id="mirror"><string name="material" value="none"/></bsdf>')
    return parts


def _material(i: int, meshes: int) -> str:
    """Mesh *i*'s BSDF id: the last :data:`GLASS` are glass, the rest alternate textured and
    plain colours."""
    if i >= meshes - GLASS:
        return "glass"
    return f"t{(i // 2) % TEXTURES}" if i % 2 == 0 else f"m{(i // 2) % PLAIN}"


def _room(width: int, height: int, spp: int, max_depth: int) -> list[str]:
    """Floor, back and left walls, the mirror, the sun and sky and the sensor."""

    def rect(name: str, ref: str, transform: str) -> str:
        return (
            f'<shape type="rectangle" id="{name}"><ref id="{ref}"/>'
            f'<transform name="to_world">{transform}</transform></shape>'
        )

    return [
        rect("floor", "t0", '<scale value="5"/>'),
        rect(
            "back_wall",
            "m0",
            '<scale x="5" y="1.5"/><rotate x="1" angle="90"/><translate y="5" z="1.5"/>',
        ),
        rect(
            "left_wall",
            "m1",
            '<scale x="5" y="1.5"/><rotate x="1" angle="90"/><rotate z="1" angle="90"/><translate x="-5" z="1.5"/>',
        ),
        rect(
            "wall_mirror",
            "mirror",
            '<scale x="1.5" y="1"/><rotate x="1" angle="90"/><rotate z="1" angle="90"/><translate x="-4.95" z="1.5"/>',
        ),
        f'<emitter type="sunsky"><float name="hour" value="{SUN_HOUR}"/>'
        '<float name="turbidity" value="3"/></emitter>',
        '<sensor type="perspective"><float name="fov" value="65"/><transform name="to_world">'
        '<lookat origin="3, -6, 2.5" target="-0.5, 0, 0.3" up="0, 0, 1"/></transform>'
        f'<sampler type="independent"><integer name="sample_count" value="{spp}"/></sampler>'
        f'<film type="hdrfilm"><integer name="width" value="{width}"/>'
        f'<integer name="height" value="{height}"/></film></sensor>',
    ]


def write_interior(
    folder: Path,
    meshes: int = MESHES,
    size: tuple[int, int] = (WIDTH, HEIGHT),
    preset: str = PRESET,
) -> Path:
    """The interior (module docstring) in *folder*, of *meshes* boxes at *size* (width,
    height) pixels, at *preset*'s spp and depth; the file's path."""
    render = get_preset(preset).render
    (folder / "meshes").mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(42)
    write_text_file(folder / "meshes" / "box.obj", box_obj(GRID, uv=True))
    parts = [
        '<scene version="3.0.0">',
        f'<integrator type="path"><integer name="max_depth" value="{render.max_depth}"/></integrator>',
        *_bsdfs(folder, rng),
    ]
    side = int(np.ceil(np.sqrt(meshes)))
    for i in range(meshes):
        x, y = (i % side) / side * 8 - 4, (i // side) / side * 8 - 4
        parts.append(
            f'<shape type="obj" id="obj{i:03d}"><string name="filename" value="meshes/box.obj"/>'
            f'<ref id="{_material(i, meshes)}"/><transform name="to_world"><scale value="0.12"/>'
            f'<translate x="{x:.4f}" y="{y:.4f}" z="0.12"/></transform></shape>'
        )
    parts += _room(*size, render.spp, render.max_depth)
    parts.append("</scene>")
    path = folder / "interior.xml"
    write_text_file(path, "\n".join(parts))
    return path


def _rss_bytes() -> int:
    """This process's peak resident size (``ru_maxrss``: KiB on Linux, bytes on macOS)."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return int(peak if sys.platform == "darwin" else peak * 1024)


@contextmanager
def _staged(seconds: dict[str, float], passes: dict[str, float]) -> Iterator[None]:
    """Time the sample build's stages into *seconds*, by wrapping the functions it calls
    (restored on exit): load, render, ground truth; write is the export less the ground truth.
    *passes* gets the render's own seconds per pass group (``meta["timings"]``)."""

    def timed(module: Any, name: str, stage: str) -> Callable[..., Any]:
        inner = getattr(module, name)

        def wrapper(*args: Any, **kwargs: Any) -> Any:
            start = time.perf_counter()
            try:
                out = inner(*args, **kwargs)
            finally:
                seconds[stage] = seconds.get(stage, 0.0) + time.perf_counter() - start
            if stage == "render":
                passes.update({k: t["seconds"] for k, t in out.meta.get("timings", {}).items()})
            return out

        setattr(module, name, wrapper)
        return inner

    wrapped = [
        (dataset, "_task_scene", "load"),
        (dataset, "render_batches", "render"),
        (dataset, "export_sample", "export"),
        (writer, "compute_ground_truth", "ground_truth"),
    ]
    originals = [(module, name, timed(module, name, stage)) for module, name, stage in wrapped]
    try:
        yield
    finally:
        for module, name, inner in originals:
            setattr(module, name, inner)


def _ours(path: str, out: str, preset: str) -> dict[str, Any]:
    """A one-sample ground-truth build of *path* as ``render PATH --ground-truth --approximate
    --preset PRESET`` makes it, in this (fresh) process:
    the stages' seconds, the peak resident memory and the sample folder's size."""
    seconds: dict[str, float] = {}
    passes: dict[str, float] = {}
    start = time.perf_counter()
    with _staged(seconds, passes):
        # what ``render PATH --ground-truth --approximate --preset PRESET`` builds (the
        # pipeline's call, without the command line above it: bench sits below cli)
        config = get_preset(preset).with_options(source=files_source([path], approximate=True))
        report = dataset.build_dataset(out, config)
    seconds["total"] = time.perf_counter() - start
    if report.failed:
        raise RuntimeError(f"render --ground-truth failed: {report.failed}")
    seconds["write"] = seconds.pop("export") - seconds["ground_truth"]
    # the dataset's card, gallery and manifest, and the imports
    seconds["other"] = seconds["total"] - sum(seconds[s] for s in STAGES)
    folder_bytes = sum(f.stat().st_size for f in Path(out).rglob("*") if f.is_file())
    return {
        "seconds": seconds,
        "render_pass_seconds": passes,
        "peak_bytes": _rss_bytes(),
        "folder_bytes": folder_bytes,
    }


def _mitsuba(path: str, kind: str) -> dict[str, Any]:
    """``mitsuba.load_file`` and one ``mitsuba.render`` at the file's spp in this process."""

    mi = import_mitsuba()
    variant = choose_variant("spectral" if kind == "spectral" else "rgb")
    mi.set_variant(variant)
    start = time.perf_counter()
    scene = mi.load_file(path)
    loaded = time.perf_counter()
    image = np.array(mi.render(scene, seed=0), dtype=np.float32)
    done = time.perf_counter()
    return {
        "variant": variant,
        "seconds": {"load": loaded - start, "render": done - loaded, "total": done - start},
        "peak_bytes": _rss_bytes(),
        "mean": float(image.mean()),
    }


def _in_fresh_process(fn: Callable[..., dict[str, Any]], *args: str) -> dict[str, Any]:
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=context) as pool:
        return pool.submit(fn, *args).result()


def run(out_dir: Path) -> dict[str, Any]:
    render = get_preset(PRESET).render
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory(dir=out_dir) as tmp:
        path = str(write_interior(Path(tmp) / "scene", MESHES, (WIDTH, HEIGHT), PRESET))
        ours = _in_fresh_process(_ours, path, str(Path(tmp) / "out"), PRESET)
        spectral = _in_fresh_process(_mitsuba, path, "spectral")
        rgb = _in_fresh_process(_mitsuba, path, "rgb")
    ratio = ours["seconds"]["total"] / spectral["seconds"]["total"]
    return {
        "scene": (
            f"{MESHES} OBJ boxes x 432 faces ({GLASS} glass), {TEXTURES} bitmap textures, "
            f"{PLAIN} colours, a mirror, sunsky (--approximate), {WIDTH}x{HEIGHT}"
        ),
        "preset": {
            "name": PRESET,
            "spp": render.spp,
            "spectral_spp": render.spectral_spp,
            "max_depth": render.max_depth,
            "modes": list(render.modes),
        },
        "spectrinsic": ours,
        "mitsuba_path_spectral": spectral,
        "mitsuba_path_rgb": rgb,
        "time_ratio_to_spectral_path": ratio,
        "time_ratio_to_rgb_path": ours["seconds"]["total"] / rgb["seconds"]["total"],
        "time_goal": TIME_GOAL,
        "memory_goal_bytes": MEMORY_GOAL_BYTES,
        "met": ratio <= TIME_GOAL and ours["peak_bytes"] <= MEMORY_GOAL_BYTES,
        "cores": os.cpu_count(),
        "load_average_before_after": [load_before[0], os.getloadavg()[0]],
    }
