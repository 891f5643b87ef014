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

from ..errors import RenderError, SceneError
from ..gt_export.folders.outfolder import check_output_folder
from ..gt_export.folders.staged_output import staged_output
from ..pipeline.presets import DatasetConfig, get_preset
from ..pipeline.source_plan import files_source
from ..render import (
    RenderResult,
    RenderSettings,
    choose_variant,
    count_passes,
    get_mode,
    render_scene,
)
from ..render.algebra.modes import RENDER_MODES
from ..render.base.plugins import MAX_PATH_DEPTH
from ..render.budget import check_render_size
from ..render.settings import DEFAULT_INTEGRATOR, INTEGRATORS
from ..render.settings import DEFAULT_MODES as RENDER_DEFAULT_MODES
from ..scenes.mitsuba_xml import render_hints_line, xml_notes
from ..scenes.model import Scene
from ..scenes.sample_id import SampleId
from ..scenes.sources import FILE_SIZE, is_scene_file, takes_asset_colours
from . import dataset as cli_dataset
from .dataset_layers import add_layer_options, given_layer_options, layer_changes
from .dataset_source import add_semantic_map_option, material_map, parse_resolution, semantic_map
from .render_files import write_render
from .render_scene import load_scene_argument

__all__ = ["register", "run", "requested_size"]

DEFAULT_MODES = ",".join(RENDER_DEFAULT_MODES)


def _modes_help() -> str:
    return "; ".join(f"{m.name}: {m.description}" for m in RENDER_MODES.values())


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
        f"Modes: {_modes_help()}. The pass counts are those of --integrator passes; the "
        "default single integrator renders every diagonal mode in one path traversal.",
    )
    _add_scene_options(p)
    _add_output_options(p)
    _add_sampling_options(p, default)
    _add_size_options(p, default)
    _add_pass_options(p, default)
    _add_ground_truth_options(p)
    add_layer_options(
        p.add_argument_group(
            "ground-truth layers (with --ground-truth; the layer options of `spectrinsic dataset`)"
        )
    )
    _add_material_options(p)
    p.set_defaults(func=run)


def _add_scene_options(p: Any) -> None:
    """The scene and, for library scenes, its condition and view."""
    p.add_argument(
        "scene",
        metavar="SCENE",
        help="library scene name (e.g. room-living) or a scene file (.yaml, .xml, .blend, .obj/.ply/.glb)",
    )
    p.add_argument(
        "--condition",
        default=None,
        help="library scenes: illumination condition (default: white)",
    )
    p.add_argument(
        "--view", type=int, default=None, help="library scenes: camera viewpoint (default: 0)"
    )


def _add_output_options(p: Any) -> None:
    """The render modes and the output folder."""
    p.add_argument(
        "--modes",
        default=None,
        help=f"comma-separated render modes (default: {DEFAULT_MODES}; with --ground-truth the "
        "preset's)",
    )
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="output folder")


def _add_sampling_options(p: Any, default: DatasetConfig) -> None:
    """Samples per pixel and seed."""
    p.add_argument(
        "--spp",
        type=int,
        default=None,
        help=f"samples per pixel of every pass (default: the default preset's "
        f"{default.render.spp}, and {default.render.spectral_spp or default.render.spp} for a "
        "spectral pass; with --ground-truth the chosen preset's)",
    )
    p.add_argument(
        "--seed", type=int, default=0, help="sampler seed and library illuminant seed (default: 0)"
    )


def _add_size_options(p: Any, default: DatasetConfig) -> None:
    """The image size."""
    p.add_argument(
        "--resolution",
        default=None,
        metavar="WxH",
        help="image size, e.g. 256x256 (default: a scene file's own camera size; library "
        f"scenes {default.width}x{default.height}, or the --ground-truth preset's)",
    )
    p.add_argument("--width", type=int, default=None, help="image width (prefer --resolution)")
    p.add_argument("--height", type=int, default=None, help="image height (prefer --resolution)")


def _add_pass_options(p: Any, default: DatasetConfig) -> None:
    """Path depth, backend, the extra images and the integrator."""
    p.add_argument(
        "--max-depth",
        type=int,
        default=None,
        help="longest path, 2 = direct light only (default: a Mitsuba XML file's max_depth, "
        f"else {default.render.max_depth}; with --ground-truth the preset's)",
    )
    p.add_argument(
        "--variant", default=None, help="Mitsuba backend or variant (default: best usable)"
    )
    p.add_argument(
        "--per-light",
        action="store_true",
        help="also write one image per light (a --ground-truth sample always holds its lights' shares)",
    )
    p.add_argument("--direct", action="store_true", help="also write direct-light-only images")
    p.add_argument(
        "--no-aovs",
        action="store_true",
        help="skip coverage/id/depth/normal maps (not with --ground-truth: its layers need them)",
    )
    p.add_argument(
        "--integrator",
        choices=INTEGRATORS,
        default=None,
        help="diagonal modes from one traversal (single) or K/3 passes per mode and "
        f"one scene per light (passes); same images (default: {DEFAULT_INTEGRATOR})",
    )


def _add_ground_truth_options(p: Any) -> None:
    """``--ground-truth``: a one-sample dataset instead of raw passes."""
    p.add_argument(
        "--ground-truth",
        action="store_true",
        help="write every ground-truth layer instead of raw passes: a one-sample dataset "
        "built by the same path as `spectrinsic dataset --scenes` (uses --preset)",
    )
    p.add_argument(
        "--preset",
        default=None,
        help="with --ground-truth: quality preset (default: default, the same spp, depth "
        "and library size as a plain render; preview for a quick look)",
    )
    p.add_argument(
        "--new-sample",
        action="store_true",
        help="with --ground-truth: render a scene a generated build saved as a new sample "
        "(id from the file name, seed from --seed) instead of reproducing its own",
    )
    p.add_argument(
        "--ignore-disk-space",
        action="store_true",
        help="with --ground-truth: write the sample even if its estimated size is more than "
        "the free space where --out lies",
    )


def _add_material_options(p: Any) -> None:
    """Spectra of the materials of .blend and mesh files."""
    p.add_argument(
        "--material-map",
        metavar="FILE",
        default=None,
        help="material name -> spectrum map for .blend and mesh files",
    )
    p.add_argument(
        "--default-spectrum",
        metavar="NAME",
        default=None,
        help="reflectance of unmapped materials in .blend and mesh files",
    )
    add_semantic_map_option(p)
    p.add_argument(
        "--colours-from-asset",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="give unmapped materials the colour or texture their file states (glTF base "
        "colour and texture, OBJ/MTL Kd and map_Kd, Principled Base Color; default: on where "
        "the file states one; given explicitly for a file that states none: refused)",
    )
    p.add_argument(
        "--approximate",
        action="store_true",
        help="Mitsuba XML: approximate what has no exact ground truth (glass, bitmaps other "
        "than a diffuse reflectance, environment maps...) instead of refusing it, one line "
        "saying what",
    )


#: Largest sampler seed and samples per pixel Mitsuba takes (both are unsigned 32-bit).
UINT32_MAX = 2**32 - 1


def _check_size_options(args: argparse.Namespace) -> None:
    """Every number and name the render needs, checked before anything is loaded or written."""
    for option, value in (("--width", args.width), ("--height", args.height), ("--spp", args.spp)):
        if value is not None and value < 1:
            raise RenderError(f"{option} {value}; expected a positive integer")
    if args.spp is not None and args.spp > UINT32_MAX:
        raise RenderError(f"--spp {args.spp}; expected at most {UINT32_MAX}")
    if not 0 <= args.seed <= UINT32_MAX:
        raise RenderError(f"--seed {args.seed}; expected a whole number from 0 to {UINT32_MAX}")
    if args.max_depth is not None and not 1 <= args.max_depth <= MAX_PATH_DEPTH:
        raise RenderError(
            f"--max-depth {args.max_depth}; expected 1 to {MAX_PATH_DEPTH} (2 = direct light only)"
        )
    if args.variant is not None:
        choose_variant("rgb", args.variant)  # an unknown or unusable backend, before any work
    requested_size(args)  # a malformed --resolution, before any work


def _check_source_options(args: argparse.Namespace) -> None:
    """Refuse options that do not apply to SCENE (a library name or a scene file), then give
    the library options their defaults (condition white, view 0)."""
    file = is_scene_file(args.scene)
    given = {
        "--condition": args.condition is not None,
        "--view": args.view is not None,
        "--material-map": args.material_map is not None,
        "--default-spectrum": args.default_spectrum is not None,
        "--semantic-map": args.semantic_map is not None,
    }
    library_only = ("--condition", "--view")
    file_only = ("--material-map", "--default-spectrum", "--semantic-map")
    if args.approximate and Path(args.scene).suffix.lower() != ".xml":
        raise RenderError(f"--approximate applies to Mitsuba XML scenes; {args.scene!r} is not one")
    for option in library_only if file else file_only:
        if given[option]:
            kind = "a scene file" if file else "a library scene"
            applies = "library scenes" if file else "scene files"
            raise RenderError(f"{option} applies to {applies}; {args.scene!r} is {kind}")
    if args.colours_from_asset is True and not (file and takes_asset_colours(args.scene)):
        raise RenderError(
            f"--colours-from-asset applies to glTF/GLB, OBJ/MTL and .blend files; {args.scene!r} states "
            "no base colours"
        )
    args.condition = "white" if args.condition is None else args.condition
    args.view = 0 if args.view is None else args.view


def requested_size(args: argparse.Namespace) -> tuple[int, int] | None:
    """``--resolution`` (or ``--width``/``--height``, a side left out taking the other's or a
    file's default), or ``None`` when no size was asked for."""
    if args.resolution is not None:
        if args.width is not None or args.height is not None:
            raise RenderError("--resolution with --width/--height; give one of them")
        return parse_resolution(args.resolution)
    if args.width is None and args.height is None:
        return None
    return args.width or args.height or FILE_SIZE, args.height or args.width or FILE_SIZE


def _ground_truth(args: argparse.Namespace) -> int:
    """``render --ground-truth``: a one-sample dataset (library name or scene file), built by
    the same call as ``spectrinsic dataset`` (:func:`spectrinsic.cli.dataset.build`)."""
    changes: dict[str, Any] = {}
    for option, given in (("--per-light", args.per_light), ("--no-aovs", args.no_aovs)):
        if given:
            raise RenderError(
                f"{option} applies to a raw render; a --ground-truth sample always holds every "
                "light's share and the AOV layers"
            )
    if args.spp is not None:
        changes["spp"] = args.spp
    if args.modes is not None:  # the sample renders (and records) these modes and no others
        changes["modes"] = tuple(_parse_modes(args))
    if args.max_depth is not None:
        changes["max_depth"] = args.max_depth
    if args.integrator is not None:
        changes["integrator"] = args.integrator
    if args.direct:
        changes["direct"] = True
    if args.variant is not None:  # the backend of the one-sample dataset too
        changes["variant"] = args.variant
    size = requested_size(args)
    if size is not None:
        changes["width"], changes["height"] = size
    changes.update(layer_changes(args))  # the layer options shared with `dataset`
    only = None
    if is_scene_file(args.scene):
        changes["source"] = files_source(
            [args.scene],
            materials=material_map(args.material_map),
            default_spectrum=args.default_spectrum,
            resolution=size,
            new_sample=args.new_sample,
            colours_from_asset=args.colours_from_asset is not False,
            approximate=args.approximate,
            semantic=semantic_map(args.semantic_map),
        )
    else:
        only = str(SampleId(args.scene, args.view, args.condition))
    preset = "default" if args.preset is None else args.preset
    config = get_preset(preset, seed=args.seed).with_options(**changes)
    if not is_scene_file(args.scene) and not getattr(args, "quiet", False):
        why = "--resolution" if size else f"preset {preset!r}"
        print(f"spectrinsic render: {config.width}x{config.height} ({why})", file=sys.stderr)
    cli_dataset.preflight(
        args.out,
        config,
        data_dir=getattr(args, "data_dir", None),
        quiet=getattr(args, "quiet", False),
    )
    return cli_dataset.build(
        args.out,
        config,
        only=only,
        data_dir=getattr(args, "data_dir", None),
        quiet=getattr(args, "quiet", False),
        disk_check=not args.ignore_disk_space,
    )


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
    _check_size_options(args)
    _check_source_options(args)
    if args.ground_truth:
        return _ground_truth(args)
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
    settings = _render_settings(args, _parse_modes(args))
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
        n_lights=len(scene.lights),
        data_dir=data_dir,
    )
    with staged_output(Path(args.out)) as stage:  # a failed run leaves --out as it was
        result = _render_with_progress(args, scene, settings, data_dir)
        paths = write_render(stage, scene, result, data_dir=data_dir)
    _print_timings(result, {k: Path(args.out) / v.relative_to(stage) for k, v in paths.items()})
    return 0


def _parse_modes(args: argparse.Namespace) -> list[str]:
    """The ``--modes`` names, each checked to be a known render mode."""
    given = DEFAULT_MODES if args.modes is None else args.modes
    modes = [m.strip() for m in str(given).split(",") if m.strip()]
    if not modes:
        raise SceneError(
            f"--modes {args.modes!r}: expected a comma-separated list such as {DEFAULT_MODES}"
        )
    for mode in modes:
        get_mode(mode)
    return modes


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
        for note in xml_notes(scene):
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
