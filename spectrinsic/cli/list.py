"""``spectrinsic list WHAT``: what spectrinsic knows, read from its own registries.

One name per line, then (after two spaces) a short description where the registry has one, so
``spectrinsic list scenes | cut -d' ' -f1`` gives the bare names. Nothing here names a scene,
method or preset by hand: every list is read from the registry that dispatches on those names
(the scene library, :data:`~spectrinsic.scenes.CONDITIONS`, the spectrum registry, the
decomposer registry with its plugins, the scene generators, the dataset presets).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from collections.abc import Callable

from ..decompose.methods.registry import DECOMPOSERS, available_decomposers
from ..errors import SpectrinsicError, validate_choice
from ..pipeline.presets import PRESETS
from ..scenes.generators import GENERATORS
from ..scenes.library import CONDITION_DESCRIPTIONS, CONDITIONS, n_views, scene_names
from ..scenes.library_gloss import GLOSSY_SUFFIX
from ..spectra import get_sensors, list_spectra
from ..spectra.camera_model import CAMERA_PRESETS
from ..spectra.registry import SPECTRUM_FAMILIES, SPECTRUM_FAMILY_NOTES

__all__ = ["register", "run", "catalogue", "CATALOGUES"]

#: One (name, description) row of a listing; the description may be empty.
Row = tuple[str, str]


#: A sentence ends at a full stop and a space, not after an abbreviation ("et al. 2009").
_SENTENCE_END = re.compile(r"(?<!\bal)(?<!\be\.g)(?<!\bi\.e)\.(?:\s|$)")


def _first_sentence(text: str | None) -> str:
    """The first sentence of a docstring, on one line, without its full stop (``""`` for none)."""
    flat = " ".join((text or "").split())
    return _SENTENCE_END.split(flat, maxsplit=1)[0]


def _scenes(_data_dir: str | None) -> list[Row]:
    """Every library scene: the thesis' 11 and their 11 ``*-glossy`` variants."""
    objects = set(scene_names("object"))
    glossy = scene_names("glossy")
    return [
        (
            name,
            f"{'single object' if name.removesuffix(GLOSSY_SUFFIX) in objects else 'room'}, "
            f"{n_views(name)} view{'s' if n_views(name) > 1 else ''}"
            + (", glossy variant (not in the default layout)" if name in glossy else ""),
        )
        for name in scene_names() + glossy
    ]


def _conditions(_data_dir: str | None) -> list[Row]:
    return [(name, CONDITION_DESCRIPTIONS.get(name, "")) for name in CONDITIONS]


def _spectra(_data_dir: str | None) -> list[Row]:
    return [(family, SPECTRUM_FAMILY_NOTES.get(family, "")) for family in SPECTRUM_FAMILIES]


def _cameras(data_dir: str | None) -> list[Row]:
    """The ``--camera`` presets (a whole camera: curves, noise, ADC), then every sensor set."""
    presets = [
        (
            name,
            f"--camera preset: {model.sensitivities}, {model.adc_bits}-bit, full well "
            f"{model.full_well_e:.0f} e-, read noise {model.read_noise_e:g} e-, ISO {model.iso:g}"
            f" (files sensor-{name}.*, layers */{model.sensitivities.split(':', 1)[-1]})",
        )
        for name, model in CAMERA_PRESETS.items()
    ]
    return presets + [
        (name, get_sensors(name, data_dir=data_dir).source or "")
        for name in list_spectra("camera", data_dir=data_dir)
    ]


def _methods(_data_dir: str | None) -> list[Row]:
    return [
        (name, ("" if name in DECOMPOSERS else "plugin: ") + _first_sentence(factory.__doc__))
        for name, factory in available_decomposers().items()
    ]


def _generators(_data_dir: str | None) -> list[Row]:
    rows = []
    for name, layout in GENERATORS.items():
        text = _first_sentence(sys.modules[layout.__module__].__doc__)
        rows.append((name, text.removeprefix(f"``{name}``:").strip()))
    return rows


def _presets(_data_dir: str | None) -> list[Row]:
    rows = []
    for name, cfg in PRESETS.items():
        r = cfg.render
        spp = f"{r.batches} batches × {r.batch_spp} spp" if r.batches > 1 else f"{r.spp} spp"
        extras = [", ".join(r.modes)] + (["denoised"] if cfg.denoise else [])
        if r.noise_target is not None:
            extras.append(f"noise target {r.noise_target:g}")
        rows.append((name, f"{cfg.width}×{cfg.height}, {spp}; " + "; ".join(extras)))
    return rows


#: What ``list`` can list, in the order ``--help`` names them, with the registry behind each.
CATALOGUES: dict[str, tuple[Callable[[str | None], list[Row]], str]] = {
    "scenes": (_scenes, "library scenes (spectrinsic.scenes.library)"),
    "conditions": (_conditions, "illumination conditions of the library scenes"),
    "spectra": (_spectra, "spectrum families; 'list spectra FAMILY' names a family's spectra"),
    "cameras": (
        _cameras,
        "camera presets (dataset --camera), then camera sensitivities (more with --data-dir)",
    ),
    "methods": (_methods, "decomposers, bundled then plugins"),
    "generators": (_generators, "procedural scene generators (dataset --generator)"),
    "presets": (_presets, "dataset presets (dataset --preset)"),
}


def catalogue(what: str, *, family: str | None = None, data_dir: str | None = None) -> list[Row]:
    """The rows of ``spectrinsic list WHAT [FAMILY]``.

    Raises
    ------
    SpectrinsicError
        An unknown *what* (with a did-you-mean), a *family* for anything but ``spectra``, or a
        family that cannot be enumerated.
    """
    validate_choice(what, CATALOGUES, "listing", error=SpectrinsicError)
    if family is None:
        return CATALOGUES[what][0](data_dir)
    if what != "spectra":
        raise SpectrinsicError(f"list {what} {family!r}: only 'list spectra' takes a FAMILY")

    return [(name, "") for name in list_spectra(family, data_dir=data_dir)]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "list",
        help="list what spectrinsic knows: " + ", ".join(CATALOGUES),
        description="Print one name per line, with a short description where there is one: "
        + "; ".join(f"{k}: {v[1]}" for k, v in CATALOGUES.items())
        + ".",
    )
    p.add_argument(
        "what", metavar="WHAT", choices=list(CATALOGUES), help="one of " + ", ".join(CATALOGUES)
    )
    p.add_argument(
        "family",
        metavar="FAMILY",
        nargs="?",
        default=None,
        help="with 'spectra': list every spectrum of this family (e.g. munsell, cie)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    rows = catalogue(args.what, family=args.family, data_dir=args.data_dir)
    width = max((len(name) for name, _ in rows), default=0)
    try:
        for name, text in rows:
            print(f"{name:<{width}}  {text}" if text else name)
        sys.stdout.flush()
    except BrokenPipeError:  # `spectrinsic list ... | head`: the reader has all it wanted
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return 0
