"""The command line: help, info, and one-line errors for bad input."""

from __future__ import annotations

import subprocess
import sys

import pytest

from spectrinsic.cli import build_parser, main


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
    out = subprocess.run([sys.executable, "-P", "-m", "spectrinsic", "--help"],
                         capture_output=True, text=True, check=True).stdout
    assert "spectrinsic" in out


def test_every_registered_command_has_help():
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    assert set(sub.choices) >= {"info"}
    for name, p in sub.choices.items():
        assert p.description or p.format_help(), name


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
