"""The scene files of ``spectrinsic dataset --scenes`` (and ``render --ground-truth``) before a
build: whether each reads as a valid scene, and what applies to it (its size, its sample, what
its read fixed or approximated)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from ..errors import DatasetError, SpectrinsicError
from ..pipeline.presets import DatasetConfig
from ..pipeline.source_plan import check_scene_integrator, file_sample, spec_file_source
from ..render.base.variants import import_mitsuba
from ..scenes.mitsuba_xml import render_hints_line
from ..scenes.model import Scene
from ..scenes.reading_notes import reading_notes
from ..spectra import get_spectrum

__all__ = ["check_scene_files", "source_notes"]


def source_notes(config: DatasetConfig) -> list[str]:
    """What applies to each scene file of *config* (``--scenes``, ``render --ground-truth``):
    its size (the file's camera or --resolution) and its sample (a saved one, reproduced, or a
    new one); empty for the library and generators."""
    spec = json.loads(config.source or "{}")
    notes = []
    for entry in spec.get("scenes", ()):
        size = spec.get("resolution")
        where = (
            f"{size[0]}x{size[1]} (--resolution)"
            if size
            else "the file's camera size (--resolution to change it)"
        )
        sid, seed = file_sample(entry["path"], new_sample=bool(spec.get("new_sample")))
        sample = (
            f"reproduces its saved sample {sid} with seed {seed} (--new-sample for a new one)"
            if seed is not None
            else f"sample {sid}"
        )
        notes.append(f"{Path(entry['path']).name}: {where}; {sample}")
    return notes


def check_scene_files(
    config: DatasetConfig, data_dir: str | None, *, quiet: bool = False
) -> list[Scene]:
    """``--scenes``: every file reads as a valid scene with this material map and default
    spectrum, before the folder is stamped with the config (a bad file is an input error, not
    a failed sample); what a file's read fixed or approximated, and the spp and depth that
    apply to it (the preset's), are said on stderr unless *quiet*. Returns the scenes read."""
    spec = json.loads(config.source or "{}")
    if "scenes" not in spec:
        return []
    materials = spec.get("materials") or {}
    named = [("--default-spectrum", spec.get("default_spectrum"))]
    named += [(f"--material-map entry {k!r}", v) for k, v in sorted(materials.items())]
    for option, name in named:
        try:
            if name is not None:
                get_spectrum(name, data_dir=data_dir)
        except SpectrinsicError as exc:
            raise DatasetError(f"{option} {name!r}: {exc}") from exc
    import_mitsuba()  # set up before a Mitsuba XML read imports it (the libLLVM Dr.Jit loads)
    scenes = []
    for entry in spec["scenes"]:
        scene = spec_file_source(spec, entry["path"]).build(data_dir)
        check_scene_integrator(config, scene, entry["path"])  # every sample would fail
        if not quiet:
            for note in reading_notes(scene):
                print(f"spectrinsic dataset: {note}", file=sys.stderr)
            given = f"the dataset's settings (preset {config.preset!r} and options)"
            line = render_hints_line(scene, config.render.spp, config.render.max_depth, given)
            if line is not None:
                print(f"spectrinsic dataset: {line}", file=sys.stderr)
        scenes.append(scene)
    return scenes
