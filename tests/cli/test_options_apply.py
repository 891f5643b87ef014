"""Every option of every verb is honoured or refused in one line: none is silently ignored.

The walk reads every verb's argparse parser. Each option is either one that applies in every
mode of its verb (:data:`EVERYWHERE`) or one that applies to some modes only
(:data:`ONLY_IN`), with a command line giving it where it does not apply; that command must
end with status 2 and one line on stderr naming the option, before any work (no ``--out``).
A new option fails the walk until it is placed in one of the two tables.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from spectrinsic.cli import build_parser, main

#: Options of every verb (the global ones) and the options that apply in every mode of a verb.
GLOBAL = {"--data-dir", "--debug", "--help", "--quiet", "--verbose"}
EVERYWHERE: dict[str, set[str]] = {
    "info": set(),
    "list": set(),
    "check": {"--max-per-sample", "--noise", "--noise-threshold", "--max-residual-share"},
    "relight": {"--keep-transport", "--light", "--out", "--power", "--scene-dir"},
    "export": {"--layers", "--out", "--samples-per-shard"},
    "study": {"--out", "--seed"},
    "train": {
        "--batch", "--checkpoint-every", "--crop", "--device", "--layers", "--lr", "--out",
        "--relight", "--resume", "--samples", "--seed", "--steps",
    },
    "evaluate": {"--methods", "--mit", "--out", "--predictions", "--samples"},
    "render": {
        "--direct", "--ground-truth", "--height", "--integrator", "--max-depth", "--modes",
        "--out", "--resolution", "--seed", "--spp", "--variant", "--width",
    },
    "dataset": {
        "--batches", "--camera", "--direct", "--generator", "--ignore-disk-space",
        "--integrator", "--no-denoise", "--noise-target", "--only", "--out", "--preset",
        "--rebuild", "--relight", "--resolution", "--scenes", "--scheduler", "--seed",
        "--spectral-layers", "--spectral-spp", "--split-fractions", "--spp",
        "--store-transport", "--threads", "--variant", "--workers", "--working-space",
    },
}  # fmt: skip

#: ``{verb: {option: (arguments after the verb, where the option does not apply)}}``; ``{out}``
#: is the output folder, ``{yaml}`` a small scene file, ``{map}`` a material map.
_RENDER_LIB = ["obj-box", "--out", "{out}"]
_RENDER_FILE = ["{yaml}", "--out", "{out}"]
_LIBRARY_BUILD = ["--out", "{out}", "--preset", "preview"]
ONLY_IN: dict[str, dict[str, list[str]]] = {
    "render": {
        "--condition": [*_RENDER_FILE, "--condition", "white"],
        "--view": [*_RENDER_FILE, "--view", "0"],
        "--material-map": [*_RENDER_LIB, "--material-map", "{map}"],
        "--default-spectrum": [*_RENDER_LIB, "--default-spectrum", "flat:0.5"],
        "--colours-from-asset": [*_RENDER_FILE, "--colours-from-asset"],
        "--ignore-disk-space": [*_RENDER_LIB, "--ignore-disk-space"],
        "--new-sample": [*_RENDER_LIB, "--new-sample"],
        "--preset": [*_RENDER_LIB, "--preset", "preview"],
        "--per-light": [*_RENDER_LIB, "--ground-truth", "--per-light"],
        "--no-aovs": [*_RENDER_LIB, "--ground-truth", "--no-aovs"],
        "--approximate": [*_RENDER_FILE, "--approximate"],
        "--semantic-map": [*_RENDER_LIB, "--ground-truth", "--semantic-map", "{map}"],
        "--camera": [*_RENDER_LIB, "--camera", "nikon-5100-npl"],
        "--spectral-layers": [*_RENDER_LIB, "--spectral-layers"],
        "--working-space": [*_RENDER_LIB, "--working-space", "srgb"],
        "--store-transport": [*_RENDER_LIB, "--store-transport"],
    },
    "dataset": {
        "--count": [*_LIBRARY_BUILD, "--count", "3"],
        "--views": [*_LIBRARY_BUILD, "--views", "2"],
        "--value-range": [*_LIBRARY_BUILD, "--value-range", "3,8"],
        "--chroma-range": [*_LIBRARY_BUILD, "--chroma-range", "0,8"],
        "--light-saturation": [*_LIBRARY_BUILD, "--light-saturation", "0,0.5"],
        "--texture-fraction": [*_LIBRARY_BUILD, "--texture-fraction", "0.5"],
        "--sfu": [*_LIBRARY_BUILD, "--sfu"],
        "--glossy": [*_LIBRARY_BUILD, "--glossy", "0.5"],
        "--metallic": [*_LIBRARY_BUILD, "--metallic", "0.5"],
        "--roughness-range": [*_LIBRARY_BUILD, "--roughness-range", "0,0.2"],
        "--glass": [*_LIBRARY_BUILD, "--glass", "0.5"],
        "--mirrors": [*_LIBRARY_BUILD, "--mirrors", "0.5"],
        "--daylight-share": [*_LIBRARY_BUILD, "--daylight-share", "0.5"],
        "--material-map": [*_LIBRARY_BUILD, "--material-map", "{map}"],
        "--default-spectrum": [*_LIBRARY_BUILD, "--default-spectrum", "flat:0.5"],
        "--new-sample": [*_LIBRARY_BUILD, "--new-sample"],
        "--colours-from-asset": [*_LIBRARY_BUILD, "--colours-from-asset"],
        "--max-batches": [*_LIBRARY_BUILD, "--max-batches", "4"],
        "--approximate": [*_LIBRARY_BUILD, "--approximate"],
        "--semantic-map": [*_LIBRARY_BUILD, "--semantic-map", "{map}"],
        "--daylight-only": [*_LIBRARY_BUILD, "--daylight-only"],
    },
    "evaluate": {
        "--png-encoding": ["--dataset", "{out}-ds", "--out", "{out}", "--png-encoding", "srgb"],
        **{
            option: ["--mit", "{out}-mit", "--out", "{out}", option, *value]
            for option, value in {
                "--dataset": ["ds"],
                "--target": ["diffuse"],
                "--seed": ["1"],
                "--no-cameras": [],
                "--no-figures": [],
                "--no-estimates": [],
            }.items()
        },
    },
    "study": {
        "--include-ie": ["rendering", "--out", "{out}", "--include-ie"],
        "--camera-balance": ["rendering", "--out", "{out}", "--camera-balance", "equal-energy-white"],
        "--no-extension": ["photometric", "--out", "{out}", "--no-extension"],
        "--quality": ["photometric", "--out", "{out}", "--quality", "default"],
        "--preset": ["photometric", "--out", "{out}", "--preset", "small"],
    },
}  # fmt: skip

SCENE = (
    "name: s\nmaterials: {grey: 'flat:0.5'}\n"
    "meshes:\n  - {name: q, vertices: [[-1,-1,0],[1,-1,0],[1,1,0]], faces: [[0,1,2]], "
    "material: grey}\n"
    "lights:\n  - {kind: point, spectrum: 'cie:D65', power: 4, position: [0, 0, 2]}\n"
    "camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 16, height: 16}\n"
)


def _verbs() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def _options(parser: argparse.ArgumentParser) -> set[str]:
    """Each option's longest name (the positive one of a ``--x``/``--no-x`` pair)."""
    names = [
        [o for o in a.option_strings if not o.startswith("--no-")] or a.option_strings
        for a in parser._actions
        if a.option_strings
    ]
    return {max(n, key=len) for n in names}


def test_every_option_of_every_verb_is_placed_in_the_walk():
    verbs = _verbs()
    assert set(verbs) == set(EVERYWHERE)
    for verb, parser in verbs.items():
        placed = GLOBAL | EVERYWHERE[verb] | set(ONLY_IN.get(verb, {}))
        assert _options(parser) == placed, (
            f"{verb}: unplaced {sorted(_options(parser) - placed)}, "
            f"gone {sorted(placed - _options(parser))}"
        )
        assert not EVERYWHERE[verb] & set(ONLY_IN.get(verb, {}))


@pytest.mark.parametrize(
    "verb, option", [(v, o) for v, table in ONLY_IN.items() for o in sorted(table)]
)
def test_an_option_given_where_it_does_not_apply_is_refused_in_one_line(
    tmp_path: Path, capsys, verb: str, option: str
):
    (tmp_path / "s.yaml").write_text(SCENE)
    (tmp_path / "map.yaml").write_text("grey: 'flat:0.5'\n")
    (tmp_path / "o-mit").mkdir()
    out = tmp_path / "o"
    values = {
        "{out}": str(out),
        "{yaml}": str(tmp_path / "s.yaml"),
        "{map}": str(tmp_path / "map.yaml"),
    }
    argv = []
    for arg in ONLY_IN[verb][option]:
        for key, value in values.items():
            arg = arg.replace(key, value)
        argv.append(arg)
    rc = main(["-q", verb, *argv])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "\n" not in err and option in err, err
    assert not out.exists()
