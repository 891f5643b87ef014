"""``spectrinsic render --ground-truth``: a one-sample dataset of SCENE (a library name or a
scene file), built by the same call as ``spectrinsic dataset``
(:func:`spectrinsic.cli.dataset.build`)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..errors import RenderError
from ..pipeline.presets import get_preset
from ..pipeline.source_plan import files_source
from ..scenes import library
from ..scenes.sample_id import SampleId
from ..scenes.sources import is_scene_file
from . import dataset as cli_dataset
from .dataset_layers import layer_changes
from .dataset_source import material_map, semantic_map
from .render_options import parse_modes, requested_size

__all__ = ["ground_truth"]


def ground_truth(args: argparse.Namespace) -> int:
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
        changes["modes"] = tuple(parse_modes(args))
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
        library.check_sample(args.scene, args.view, args.condition)
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
