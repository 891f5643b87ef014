"""The options of ``spectrinsic render``: declared on the parser, and checked before any work.

Shared by the plain render (:mod:`spectrinsic.cli.render`) and the ground-truth route
(:mod:`spectrinsic.cli.render_ground_truth`), which read the same options.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..errors import RenderError, SceneError
from ..pipeline.presets import DatasetConfig
from ..render import choose_variant, get_mode
from ..render.algebra.modes import RENDER_MODES
from ..render.base.plugins import MAX_PATH_DEPTH
from ..render.settings import DEFAULT_INTEGRATOR, INTEGRATORS, UINT32_MAX
from ..render.settings import DEFAULT_MODES as RENDER_DEFAULT_MODES
from ..scenes.sources import FILE_SIZE, is_scene_file, takes_asset_colours, takes_material_map
from .dataset_layers import add_layer_options
from .dataset_source import add_semantic_map_option, parse_resolution

__all__ = [
    "DEFAULT_MODES",
    "add_render_options",
    "check_size_options",
    "check_source_options",
    "modes_help",
    "parse_modes",
    "requested_size",
]


#: The ``--modes`` default of a plain render: the render package's default modes.
DEFAULT_MODES = ",".join(RENDER_DEFAULT_MODES)


def modes_help() -> str:
    """Every render mode and what it is, for ``--help``."""
    return "; ".join(f"{m.name}: {m.description}" for m in RENDER_MODES.values())


def add_render_options(p: Any, default: DatasetConfig) -> None:
    """Every option of ``spectrinsic render``, in the order ``--help`` lists them; *default*
    (the default preset) gives the documented defaults."""
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
        help="Mitsuba XML: approximate what has no exact ground truth (a textured glass tint"
        " or plastic specular, a Beckmann roughness, a sunsky, an emitter it cannot "
        "read...; a .blend World's Sky Texture...) instead of refusing it, one line "
        "saying what",
    )


def check_size_options(args: argparse.Namespace) -> None:
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


def check_source_options(args: argparse.Namespace) -> None:
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
    if args.approximate and Path(args.scene).suffix.lower() not in (".xml", ".blend"):
        raise RenderError(
            f"--approximate applies to Mitsuba XML scenes and .blend worlds; {args.scene!r} is neither"
        )
    for option in library_only if file else file_only:
        if given[option]:
            kind = "a scene file" if file else "a library scene"
            applies = "library scenes" if file else "scene files"
            raise RenderError(f"{option} applies to {applies}; {args.scene!r} is {kind}")
    for option in ("--material-map", "--default-spectrum"):
        if file and given[option] and not takes_material_map(args.scene):
            raise RenderError(
                f"{option} applies to .blend and mesh files; {args.scene!r} states its "
                "materials' spectra itself"
            )
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


def parse_modes(args: argparse.Namespace) -> list[str]:
    """The ``--modes`` names, each checked to be a known render mode."""
    given = DEFAULT_MODES if args.modes is None else args.modes
    modes = [m.strip() for m in str(given).split(",") if m.strip()]
    if not modes:
        raise SceneError(
            f"--modes {args.modes!r}: expected a comma-separated list such as {DEFAULT_MODES}"
        )
    for mode in modes:
        get_mode(mode)
    twice = sorted({m for m in modes if modes.count(m) > 1})
    if twice:  # each mode is one set of files: a repeat would be dropped without a word
        raise SceneError(f"--modes {args.modes!r}: {twice[0]} given twice; expected each mode once")
    return modes
