"""The command line: help, info, and one-line errors for bad input."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from spectrinsic.cli import _COMMANDS, build_parser, main
from spectrinsic.cli.dataset import config_from_args


def test_help_lists_commands(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--help"])
    assert exit_info.value.code == 0
    assert "info" in capsys.readouterr().out


def test_info_reports_versions_variants_and_data(data_dir, capsys):
    assert main(["--data-dir", str(data_dir), "info"]) == 0
    out = capsys.readouterr().out
    assert "mitsuba" in out and "scalar_rgb" in out
    assert "found   sfu_barnard2002" in out


def test_bad_data_dir_is_one_line_error(tmp_path, capsys):
    code = main(["--data-dir", str(tmp_path / "nope"), "info"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err.count("\n") == 0 and "nope" in err and "does not exist" in err


def test_console_script_runs_in_a_fresh_interpreter():
    # -P: the repository root must never be on sys.path; the installed package is used.
    out = subprocess.run(
        [sys.executable, "-P", "-m", "spectrinsic", "--help"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert "spectrinsic" in out


def test_every_registered_command_has_help():
    """Each verb is listed with a one-line help and has a description of its own (the old form
    of this test, ``description or format_help()``, could not fail: format_help is never empty)."""
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    assert set(sub.choices) == {module.rsplit(".", 1)[1] for module in _COMMANDS}
    assert {"render", "dataset", "check", "export", "study", "evaluate", "list"} <= set(sub.choices)
    listed = {a.dest: a.help for a in sub._choices_actions}
    for name, p in sub.choices.items():
        assert listed.get(name), f"{name}: no help line in `spectrinsic --help`"
        assert p.description and len(p.description) > 20, f"{name}: no description"


def test_every_verb_and_option_explains_itself():
    """Issue 13: each verb has a description and every option a help text."""
    import argparse

    from spectrinsic.cli import build_parser

    parser = build_parser()
    verbs = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    missing = []
    for name, sub in verbs.choices.items():
        if not sub.description:
            missing.append(f"{name}: no description")
        for action in sub._actions:
            if not isinstance(action, argparse._HelpAction) and not action.help:
                missing.append(f"{name} {'/'.join(action.option_strings) or action.dest}: no help")
    assert not missing, missing


def test_render_reads_a_mesh_file_as_dataset_scenes_does(tmp_path, capsys):
    """Issue 18: `render x.obj` works like `render x.obj --ground-truth` (one scene-file
    dispatch, scenes.sources.load_scene_file); it failed before (read as YAML)."""
    import json

    from spectrinsic.cli import main

    obj = tmp_path / "tri.obj"
    (tmp_path / "tri.mtl").write_text("newmtl red\nKd 1 0 0\n")
    obj.write_text("mtllib tri.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n")
    (tmp_path / "map.yaml").write_text("red: 'munsell:5R 4/14'\n")
    out = tmp_path / "out"
    rc = main(
        [
            "-q",
            "render",
            str(obj),
            "--material-map",
            str(tmp_path / "map.yaml"),
            "--out",
            str(out),
            "--modes",
            "rgb3",
            "--spp",
            "1",
            "--width",
            "8",
            "--height",
            "6",
            "--no-aovs",
        ]
    )
    assert rc == 0, capsys.readouterr().err
    meta = json.loads((out / "meta.json").read_text())
    assert [m["spectrum"] for m in meta["scene"]["materials"]] == ["munsell:5R 4/14"]
    assert (meta["scene"]["camera"]["width"], meta["scene"]["camera"]["height"]) == (8, 6)
    assert (out / "rgb3.exr").is_file()


@pytest.mark.parametrize(("integrator", "diagonal_passes"), [("passes", 1 + 11), ("single", 0)])
def test_render_integrator_option_reaches_the_render(tmp_path, capsys, integrator, diagonal_passes):
    """``--integrator`` is a render setting: the passes render rgb3 in 1 pass and bands31 in 11;
    the traversal renders both (and the AOVs) in one, reported on its own line."""
    out = tmp_path / integrator
    rc = main(
        [
            "-q",
            "render",
            "obj-box",
            "--out",
            str(out),
            "--modes",
            "rgb3,bands31",
            "--spp",
            "1",
            "--width",
            "8",
            "--height",
            "8",
            "--integrator",
            integrator,
        ]
    )
    assert rc == 0
    meta = json.loads((out / "meta.json").read_text())
    assert meta["integrator"] == integrator
    assert (
        meta["timings"]["rgb3"]["passes"] + meta["timings"]["bands31"]["passes"] == diagonal_passes
    )
    assert ("traversal" in capsys.readouterr().out) == (integrator == "single")


def test_dataset_integrator_option_is_a_render_setting_outside_the_hash(tmp_path):
    """``dataset --integrator passes`` reaches every sample's render settings; the config hash
    (which decides whether a folder's samples are reused) is the default's."""
    parse = build_parser().parse_args
    default = config_from_args(parse(["dataset", "--out", str(tmp_path)]))
    passes = config_from_args(parse(["dataset", "--out", str(tmp_path), "--integrator", "passes"]))
    assert (default.render.integrator, passes.render.integrator) == ("single", "passes")
    assert passes.config_hash() == default.config_hash()
