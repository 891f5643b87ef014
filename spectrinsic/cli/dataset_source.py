"""The scene-source options of ``spectrinsic dataset`` and their parsing: library, generator
or scene files (``--generator``, ``--scenes`` and their settings), ``--material-map``,
and ``--resolution``; shared with ``render --ground-truth`` (the check of scene files before
a build: :mod:`.dataset_scene_files`)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from ..errors import DatasetError, SceneError, SpectrinsicError
from ..pipeline.source_plan import (
    files_source,
    generator_source,
)
from ..scenes.generators import GlossDistribution
from ..scenes.generators.world_defaults import GLOSSY_FRACTION, METALLIC_FRACTION, TEXTURE_FRACTION
from ..scenes.semantic import SemanticRules, read_semantic_map
from ..scenes.sources import takes_asset_colours, takes_material_map
from ..scenes.spectrum_refs import resolve_spectrum
from ..scenes.yaml_limits import load_yaml_file

__all__ = [
    "add_source_options",
    "material_map",
    "semantic_map",
    "add_semantic_map_option",
    "parse_resolution",
    "source_from_args",
]


def add_source_options(src: Any) -> None:
    """Where the scenes come from: the library (default), a generator, or scene files."""
    _add_generator_options(src)
    _add_generated_draw_options(src)
    _add_glass_options(src)
    _add_scene_file_options(src)


def _add_generator_options(src: Any) -> None:
    """Which generator, how many scenes and how many cameras each."""
    src.add_argument(
        "--generator",
        metavar="NAME",
        default=None,
        help="generate scenes procedurally: objects-on-ground or rooms",
    )
    src.add_argument("--count", type=int, default=None, metavar="N", help="generated scenes (20)")
    src.add_argument(
        "--views", type=int, default=None, metavar="V", help="cameras per generated scene (1)"
    )


def _add_daylight_option(src: Any) -> None:
    """``--daylight-share``: rooms lit also by sun and sky through a window."""
    src.add_argument(
        "--daylight-share",
        type=float,
        default=None,
        metavar="F",
        help="fraction of generated rooms closed, with a window, and lit also by a sun and a "
        "sky of CIE daylight spectra shining through it (0); sun and sky carry 20-90 %% of "
        "such a room's light flux",
    )
    src.add_argument(
        "--daylight-only",
        action="store_true",
        help="light the --daylight-share rooms by sun and sky alone, without lamps",
    )


def _add_generated_draw_options(src: Any) -> None:
    """What generated scenes draw: material ranges, light colours, SFU data, gloss."""
    _add_daylight_option(src)
    src.add_argument(
        "--value-range",
        default=None,
        metavar="LO,HI",
        help="Munsell value range of generated materials (2,9)",
    )
    src.add_argument(
        "--chroma-range",
        default=None,
        metavar="LO,HI",
        help="Munsell chroma range of generated materials (0,16)",
    )
    src.add_argument(
        "--light-saturation",
        default=None,
        metavar="LO,HI",
        help="keep only coloured lights whose |Duv| (Ohno 2013: CIE 1960 uv distance "
        "from the Planckian locus) is in LO,HI; 0.02 is visibly tinted, at most "
        "0.15 for LO (default: any, 60%% from saturated LEDs and filtered lamps)",
    )
    src.add_argument(
        "--texture-fraction",
        type=float,
        default=None,
        metavar="F",
        help="fraction of generated objects given a per-pixel spectral texture (wood rings, "
        "weave, noise over 2-3 reflectances; exact reflectance ground truth) "
        f"({TEXTURE_FRACTION:g}; 0 for none)",
    )
    src.add_argument(
        "--sfu",
        action="store_true",
        help="also draw SFU reflectances and illuminants (needs --data-dir)",
    )
    src.add_argument(
        "--glossy",
        type=float,
        default=None,
        metavar="F",
        help=f"fraction of generated materials made coated/glossy (plastic) ({GLOSSY_FRACTION:g}; "
        "--glossy 0 --metallic 0 --texture-fraction 0: the matte world)",
    )
    src.add_argument(
        "--metallic",
        type=float,
        default=None,
        metavar="F",
        help=f"fraction of generated materials made metal (Ag, Al, Au, Cu, Cr) ({METALLIC_FRACTION:g})",
    )
    src.add_argument(
        "--roughness-range",
        default=None,
        metavar="LO,HI",
        help="GGX roughness range of glossy and metal materials (0,0.3)",
    )


def _add_glass_options(src: Any) -> None:
    """Glass and mirror objects in generated scenes (off by default)."""
    for flag, what in (("--glass", "clear glass"), ("--mirrors", "perfect mirrors")):
        src.add_argument(
            flag,
            type=float,
            default=None,
            metavar="F",
            help=f"fraction of single-material objects' materials made {what} (0)",
        )


def _add_scene_file_options(src: Any) -> None:
    """The user's own scene files and how their materials get spectra."""
    src.add_argument(
        "--scenes",
        nargs="+",
        metavar="PATH",
        default=None,
        help="render your own scene files (.yaml, Mitsuba 3 .xml, .blend, .obj/.ply/.glb) with "
        "full ground truth",
    )
    src.add_argument(
        "--material-map",
        metavar="FILE",
        default=None,
        help="YAML/JSON mapping material name -> spectrum for .blend and mesh scenes",
    )
    src.add_argument(
        "--default-spectrum",
        metavar="NAME",
        default=None,
        help="reflectance of unmapped materials in .blend and mesh scenes",
    )
    src.add_argument(
        "--colours-from-asset",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="give unmapped materials the colour or texture their file states (glTF base "
        "colour and texture, OBJ/MTL Kd and map_Kd, Principled Base Color; default: on where "
        "the file states one; given explicitly for a file that states none: refused)",
    )
    add_semantic_map_option(src)
    src.add_argument(
        "--approximate",
        action="store_true",
        help="Mitsuba XML scenes: approximate what has no exact ground truth (a textured "
        "glass tint or plastic specular, a Beckmann roughness, a sunsky, an emitter it "
        "cannot read...; a .blend World's Sky Texture...) instead of refusing it, one "
        "line saying what",
    )
    src.add_argument(
        "--new-sample",
        action="store_true",
        help="render scenes a generated build saved (<dataset>/scenes/*.yaml) as new "
        "samples (id from the file name, seed from --seed) instead of "
        "reproducing their own sample (same id, same seed)",
    )


def _range(option: str, text: str) -> tuple[float, float]:
    """An option's ``LO,HI`` text as two finite floats with LO <= HI (the configuration
    records them as JSON, which has no infinity)."""
    try:
        lo, hi = (float(v) for v in text.split(","))
    except ValueError:
        raise DatasetError(f"{option} {text!r}; expected LO,HI, e.g. 2,9") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise DatasetError(f"{option} {text!r}; expected two finite numbers LO,HI, e.g. 2,9")
    if lo > hi:
        raise DatasetError(f"{option} {text!r}; expected LO <= HI")
    return lo, hi


def add_semantic_map_option(group: Any) -> None:
    """``--semantic-map FILE``, for ``dataset --scenes`` and ``render FILE --ground-truth``."""
    group.add_argument(
        "--semantic-map",
        metavar="FILE",
        default=None,
        help="scene files with ground truth: YAML/JSON rules regex -> semantic class, tried "
        "before the default name map (spectrinsic/scenes/FORMAT.md, Semantic classes)",
    )


def semantic_map(path: str | None) -> SemanticRules | None:
    """The ``--semantic-map`` file's rules (None for none); DatasetError naming it if bad."""
    if path is None:
        return None
    try:
        return read_semantic_map(path)
    except SceneError as exc:
        raise DatasetError(f"--semantic-map: {exc}") from None


def material_map(path: str | None) -> dict[str, str]:
    """The ``--material-map`` file as ``{material name: spectrum name}`` (``{}`` for none).

    A value may also be ``csv:PATH#COLUMN`` (PATH relative to the map's folder) or an inline
    ``{wavelengths: [...], values: [...]}`` (:mod:`spectrinsic.scenes.spectrum_refs`).
    """
    if path is None:
        return {}

    data = load_yaml_file(Path(path))
    if not isinstance(data, dict) or not all(
        isinstance(k, str) and isinstance(v, (str, dict)) for k, v in data.items()
    ):
        raise DatasetError(
            f"--material-map {path!r}: expected a mapping of material name -> spectrum name"
        )
    out = {}
    for k, v in data.items():
        try:
            out[k] = resolve_spectrum(v, "reflectance", Path(path).parent)
        except SpectrinsicError as exc:
            raise DatasetError(f"--material-map {path!r}: {k}: {exc}") from None
        if not isinstance(out[k], str):
            raise DatasetError(f"--material-map {path!r}: {k}: expected a spectrum name")
    return out


#: The options of generated sets and their defaults (``None`` on the parser, so that one
#: given to another source is refused rather than ignored).
GENERATOR_DEFAULTS: dict[str, Any] = {
    "count": 20,
    "views": 1,
    "value_range": "2,9",
    "chroma_range": "0,16",
    "light_saturation": None,
    "texture_fraction": TEXTURE_FRACTION,
    "sfu": False,
    "glossy": GLOSSY_FRACTION,
    "metallic": METALLIC_FRACTION,
    "roughness_range": "0,0.3",
    "glass": 0.0,
    "mirrors": 0.0,
    "daylight_share": 0.0,
    "daylight_only": False,
}
#: The options of scene files (``--scenes``).
FILE_OPTIONS = (
    "material_map",
    "default_spectrum",
    "new_sample",
    "semantic_map",
    "colours_from_asset",
    "approximate",
)


def _given(value: object) -> bool:
    """An option given on the command line (its parser default is ``None``, or ``False`` for a
    flag)."""
    return value is not None and value is not False


def _option(name: str) -> str:
    return "--" + name.replace("_", "-")


def _check_options_apply(args: argparse.Namespace) -> None:
    """Refuse a generator option without --generator and a scene-file option without --scenes
    (in one line naming it), then fill in the generator options' defaults."""
    source = "generated scenes" if args.generator else "scene files" if args.scenes else None
    what = source or "the library's scenes"
    given = [n for n in (*GENERATOR_DEFAULTS, *FILE_OPTIONS) if _given(getattr(args, n, None))]
    unused = [n for n in given if n in GENERATOR_DEFAULTS] if not args.generator else []
    if not args.scenes:
        unused += [n for n in given if n in FILE_OPTIONS]
    if unused:
        applies = "--scenes" if unused[0] in FILE_OPTIONS else "--generator"
        raise DatasetError(f"{_option(unused[0])} applies to {applies}; this build renders {what}")
    for name, value in GENERATOR_DEFAULTS.items():
        if getattr(args, name, None) is None:
            setattr(args, name, value)


def source_from_args(args: argparse.Namespace) -> str | None:
    """The config's ``source`` for --generator / --scenes (``None``: the library)."""
    if args.generator and args.scenes:
        raise DatasetError("--generator and --scenes exclude each other; give one")
    _check_options_apply(args)
    if args.generator:
        try:
            gloss = GlossDistribution(
                args.glossy,
                args.metallic,
                _range("--roughness-range", args.roughness_range),
                glass_fraction=args.glass,
                mirror_fraction=args.mirrors,
            )
        except SceneError as exc:
            raise DatasetError(
                f"--glossy/--metallic/--roughness-range/--glass/--mirrors: {exc}"
            ) from None
        return generator_source(
            args.generator,
            args.count,
            views=args.views,
            sfu=args.sfu,
            value_range=_range("--value-range", args.value_range),
            chroma_range=_range("--chroma-range", args.chroma_range),
            gloss=gloss,
            light_saturation=None
            if args.light_saturation is None
            else _range("--light-saturation", args.light_saturation),
            texture_fraction=args.texture_fraction,
            daylight_share=args.daylight_share,
            daylight_only=args.daylight_only,
        )
    if args.scenes:
        if args.colours_from_asset is True and not any(takes_asset_colours(s) for s in args.scenes):
            raise DatasetError(
                "--colours-from-asset applies to glTF/GLB, OBJ/MTL and .blend files; none of the "
                "--scenes is one"
            )
        for option, value in (
            ("--material-map", args.material_map),
            ("--default-spectrum", args.default_spectrum),
        ):
            if value is not None and not any(takes_material_map(s) for s in args.scenes):
                raise DatasetError(
                    f"{option} applies to .blend and mesh files; none of the --scenes is one "
                    "(YAML and Mitsuba XML scenes state their materials' spectra)"
                )
        size = None if args.resolution is None else parse_resolution(args.resolution)
        return files_source(
            args.scenes,
            materials=material_map(args.material_map),
            default_spectrum=args.default_spectrum,
            resolution=size,
            new_sample=getattr(args, "new_sample", False),
            colours_from_asset=args.colours_from_asset is not False,
            approximate=args.approximate,
            semantic=semantic_map(getattr(args, "semantic_map", None)),
        )
    return None


def parse_resolution(text: str) -> tuple[int, int]:
    """``WIDTHxHEIGHT`` as two positive integers."""
    w, sep, h = text.lower().partition("x")
    if not (sep and w.isdigit() and h.isdigit() and int(w) > 0 and int(h) > 0):
        raise DatasetError(
            f"--resolution {text!r}; expected WIDTHxHEIGHT of positive integers, e.g. 256x256"
        )
    return int(w), int(h)
