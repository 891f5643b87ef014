"""Help texts that are true, `list scenes` lists every scene, global flags anywhere (issue 31)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from spectrinsic.cli import build_parser, main
from spectrinsic.pipeline.presets import get_preset
from spectrinsic.scenes.library import scene_names

README = Path(__file__).resolve().parents[2] / "README.md"


def _help(capsys, *argv: str) -> str:
    with pytest.raises(SystemExit):
        main([*argv, "--help"])
    # argparse wraps at hyphens ("ground-" / "truth") by the terminal's width: undo that
    return re.sub(r"(\w)- (\w)", r"\1-\2", " ".join(capsys.readouterr().out.split()))


def test_render_help_names_its_ground_truth_and_the_single_traversal(capsys):
    text = _help(capsys, "render")
    assert "ground-truth layers come from `spectrinsic dataset`" not in text
    assert "with --ground-truth every ground-truth layer" in text
    assert "default single integrator renders every diagonal mode in one path traversal" in text
    assert f"{get_preset('default').render.spp} spp" in text


def test_readme_states_the_default_presets_spp():
    stated = re.findall(r"256², (\d+) spp", README.read_text(encoding="utf-8"))
    assert stated and {int(s) for s in stated} == {get_preset("default").render.spp}


def test_store_transport_help_agrees_with_the_readme(capsys):
    text = _help(capsys, "dataset")
    assert "no extra render with the default single integrator" in text
    assert "costs no extra render" in README.read_text(encoding="utf-8")


def test_top_level_help_says_dataset_builds_every_source(capsys):
    text = _help(capsys)
    assert "--generator" in text and "--scenes" in text and "68 library samples" in text


def test_list_scenes_lists_every_scene_glossy_variants_included(capsys):
    assert main(["list", "scenes"]) == 0
    listed = {line.split()[0] for line in capsys.readouterr().out.splitlines() if line.strip()}
    assert set(scene_names()) | set(scene_names("glossy")) <= listed
    assert len(scene_names("glossy")) == 11


@pytest.mark.parametrize(
    "argv",
    [
        ["dataset", "--out", "x", "-q", "-v", "--debug", "--data-dir", "D"],
        ["-q", "-v", "--debug", "--data-dir", "D", "dataset", "--out", "x"],
    ],
)
def test_global_flags_work_before_and_after_the_verb(argv):
    args = build_parser().parse_args(argv)
    assert (args.quiet, args.verbose, args.debug, args.data_dir) == (True, 1, True, "D")


def test_global_flags_keep_their_defaults_when_not_given():
    args = build_parser().parse_args(["check", "somewhere"])
    assert (args.quiet, args.verbose, args.debug, args.data_dir) == (False, 0, False, None)


def test_a_flag_after_the_verb_reaches_the_run(tmp_path, capsys):
    assert main(["check", str(tmp_path / "missing"), "-q"]) == 2
    err = capsys.readouterr().err
    assert "unrecognized" not in err and "does not exist" in err
