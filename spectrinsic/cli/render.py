"""``spectrinsic render``: render one scene in several modes and write the raw passes as EXR.

``SCENE`` is a library scene name (``spectrinsic.scenes.library``) or a scene file (YAML,
Mitsuba 3 XML, ``.blend`` or mesh, read as ``dataset --scenes`` reads them). For
every mode ``DIR/<mode>.exr`` holds float32 layers ``raw`` (the K raw channels, named after the
sensors, e.g. ``raw.B400``), ``xyz`` (CIE 1931 XYZ), and when asked ``direct`` and
``light<i>`` (XYZ), and ``DIR/<mode>.png`` its sRGB preview; ``DIR/aovs.exr`` holds coverage, ids, depth and normals; ``DIR/meta.json``
the render settings, variants, timings and the scene. Ground-truth layers are written by
``spectrinsic dataset``, not here.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path
from typing import Any

from tqdm import tqdm

from ..errors import RenderError
from ..gt_export.folders.outfolder import check_output_folder
from ..gt_export.folders.staged_output import staged_output
from ..pipeline.presets import get_preset
from ..render import (
    RenderResult,
    RenderSettings,
    count_passes,
    render_scene,
)
from ..render.base.plugins import MAX_PATH_DEPTH
from ..render.budget import RenderLoad, check_render_size
from ..render.settings import DEFAULT_INTEGRATOR
from ..scenes.mitsuba_xml import render_hints_line
from ..scenes.model import Scene
from ..scenes.reading_notes import reading_notes
from ..scenes.sources import is_scene_file
from .dataset_layers import given_layer_options
from .dataset_source import material_map
from .render_files import write_render
from .render_ground_truth import ground_truth
from .render_options import (
    add_render_options,
    check_size_options,
    check_source_options,
    modes_help,
    parse_modes,
    requested_size,
)
from .render_scene import load_scene_argument

__all__ = ["register", "run"]


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``render`` subcommand to the CLI's *subparsers*."""
    # one set of documented defaults: those of the dataset's default preset
    default = get_preset("default")
    p = sub.add_parser(
        "render",
        help="render a scene in several colour modes and write raw passes as EXR",
        description="Render SCENE (a library scene name, a YAML, Mitsuba 3 XML, .blend or mesh file) with Mitsuba 3 "
        "in each mode and write float32 EXR files with named channels into --out "
        "(raw passes, XYZ, AOVs; with --ground-truth every ground-truth layer, by the "
        "path of `spectrinsic dataset`). "
        f"Defaults are the dataset's default preset: {default.render.spp} spp, path depth "
        f"{default.render.max_depth}, library scenes at {default.width}x{default.height}. "
        f"Modes: {modes_help()}. The pass counts are those of --integrator passes; the "
        "default single integrator renders every diagonal mode in one path traversal.",
    )
    add_render_options(p, default)
    p.set_defaults(func=run)


def _render_settings(args: argparse.Namespace, modes: list[str]) -> RenderSettings:
    """The render settings the options give (defaults: the default preset's spp, spectral
    spp and depth; ``--spp`` sets every pass)."""
    default = get_preset("default").render
    spp, spectral = (default.spp, default.spectral_spp) if args.spp is None else (args.spp, None)
    return RenderSettings(
        spp,
        spectral_spp=spectral,
        modes=tuple(modes),
        max_depth=default.max_depth if args.max_depth is None else args.max_depth,
        variant=args.variant,
        per_light=args.per_light,
        direct=args.direct,
        aovs=not args.no_aovs,
        integrator=DEFAULT_INTEGRATOR if args.integrator is None else args.integrator,
    )


def run(args: argparse.Namespace) -> int:
    """``spectrinsic render``: check the options, load the scene, render it, write the files."""
    check_size_options(args)
    check_source_options(args)
    if args.ground_truth:
        return ground_truth(args)
    for option, given in (
        ("--ignore-disk-space", args.ignore_disk_space),  # a plain render's files are small
        ("--new-sample", args.new_sample),
        ("--preset", args.preset is not None),
        ("--semantic-map", args.semantic_map is not None),  # a plain render has no layers
    ):
        if given:
            raise RenderError(f"{option} applies only with --ground-truth")
    for option in given_layer_options(args):  # ground-truth layers: a plain render has none
        raise RenderError(
            f"{option} applies only with --ground-truth (a ground-truth layer option)"
        )
    settings = _render_settings(args, parse_modes(args))
    check_output_folder(Path(args.out))
    data_dir = getattr(args, "data_dir", None)
    scene = _load_scene(args, data_dir)
    settings = _file_settings(args, scene, settings)
    given = _given_size(args)
    if not getattr(args, "quiet", False):
        why = given or (
            "the scene file's camera" if is_scene_file(args.scene) else "the default preset's"
        )
        print(
            f"spectrinsic render: {scene.camera.width}x{scene.camera.height} ({why})",
            file=sys.stderr,
        )
    check_render_size(
        scene.camera.width,
        scene.camera.height,
        settings,
        what=given or f"scene {args.scene!r}",
        load=RenderLoad.of_scene(scene),
        data_dir=data_dir,
    )
    with staged_output(Path(args.out)) as stage:  # a failed run leaves --out as it was
        result = _render_with_progress(args, scene, settings, data_dir)
        paths = write_render(stage, scene, result, data_dir=data_dir)
    _print_timings(result, {k: Path(args.out) / v.relative_to(stage) for k, v in paths.items()})
    return 0


def _load_scene(args: argparse.Namespace, data_dir: str | None) -> Scene:
    """The ``SCENE`` argument as a Scene at the requested size (if any)."""
    size = requested_size(args)
    return load_scene_argument(
        args.scene,
        condition=args.condition,
        view=args.view,
        seed=args.seed,
        width=size[0] if size else None,
        height=size[1] if size else None,
        materials=material_map(args.material_map),
        default_spectrum=args.default_spectrum,
        data_dir=data_dir,
        colours_from_asset=args.colours_from_asset is not False,
        approximate=args.approximate,
    )


def _file_settings(
    args: argparse.Namespace, scene: Scene, settings: RenderSettings
) -> RenderSettings:
    """*settings* with a Mitsuba XML file's ``sample_count`` and ``max_depth`` where the
    command line gave no ``--spp`` / ``--max-depth``; says what it read and which applies."""
    if not getattr(args, "quiet", False):
        for note in reading_notes(scene):
            print(f"spectrinsic render: {note}", file=sys.stderr)
        line = render_hints_line(scene, args.spp, args.max_depth)
        if line is not None:
            print(f"spectrinsic render: {line}", file=sys.stderr)
    hints = scene.metadata.get("render_hints") or {}
    changes: dict[str, Any] = {}
    if args.spp is None and "spp" in hints:
        changes |= {"spp": int(hints["spp"]), "spectral_spp": None}
    if args.max_depth is None and "max_depth" in hints:
        if not 1 <= int(hints["max_depth"]) <= MAX_PATH_DEPTH:
            raise RenderError(
                f"{args.scene}: max_depth {hints['max_depth']}; expected 1 to {MAX_PATH_DEPTH} "
                "(give --max-depth)"
            )
        changes["max_depth"] = int(hints["max_depth"])
    return dataclasses.replace(settings, **changes) if changes else settings


def _given_size(args: argparse.Namespace) -> str:
    """The size options as given on the command line (empty when none was)."""
    if args.resolution:
        return f"--resolution {args.resolution}"
    return " ".join(
        f"--{k} {v}" for k, v in (("width", args.width), ("height", args.height)) if v is not None
    )


def _render_with_progress(
    args: argparse.Namespace, scene: Scene, settings: RenderSettings, data_dir: str | None
) -> RenderResult:
    """Render *scene* with a progress bar over its passes (none with --quiet)."""
    total = count_passes(scene, settings, data_dir=data_dir)
    bar = (
        None
        if getattr(args, "quiet", False)
        else tqdm(total=total, desc=f"render {scene.name}", unit="pass", file=sys.stderr)
    )
    try:
        return render_scene(
            scene,
            settings,
            seed=args.seed,
            progress=None if bar is None else bar.update,
            data_dir=data_dir,
        )
    finally:
        if bar is not None:
            bar.close()


def _print_timings(result: RenderResult, paths: dict[str, Path]) -> None:
    """One line per mode (passes, seconds, file), the single traversal's, and meta.json."""
    timings = result.meta["timings"]
    for mode in result.images:
        print(
            f"{mode:<9} {timings[mode]['passes']:>3} passes {timings[mode]['seconds']:7.2f} s  -> {paths[mode]} "
            f"(sRGB preview {paths[f'{mode}_png'].name})"
        )
    if "single" in timings:  # every diagonal mode (and the AOVs) from one traversal
        print(
            f"{'traversal':<9} {timings['single']['passes']:>3} passes {timings['single']['seconds']:7.2f} s  "
            "(all diagonal modes and lights)"
        )
    print(f"wrote {paths['meta']}")
