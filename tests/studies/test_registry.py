"""The studies registry: one protocol, one runner, the CLI verb a loop over it."""

from __future__ import annotations

import pytest

from spectrinsic.cli import build_parser
from spectrinsic.errors import StudyError
from spectrinsic.studies.reconstruction import format_table, reconstruction_table
from spectrinsic.studies.registry import STUDIES, StudyOptions, get_study, run_study


def test_every_study_has_the_four_steps_and_the_cli_offers_exactly_them():
    for name, study in STUDIES.items():
        assert study.name == name and study.summary
        assert all(
            callable(getattr(study, step)) for step in ("settings", "run", "format", "write")
        )
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    study_parser = sub.choices["study"]
    positional = next(a for a in study_parser._actions if a.dest == "study")
    assert tuple(positional.choices) == tuple(STUDIES)


def test_an_unknown_study_is_a_one_line_error_with_a_suggestion():
    with pytest.raises(StudyError, match="did you mean 'photometric'") as info:
        get_study("photometrc")
    assert "\n" not in str(info.value)


def test_options_reach_each_study_settings():
    options = StudyOptions(
        seed=7, include_ie=True, camera_balance="d65-white", extension=False, quality="preview"
    )
    photometric = get_study("photometric").settings(options)
    assert (photometric.seed, photometric.include_ie, photometric.camera_balance) == (
        7,
        True,
        "d65-white",
    )
    rendering = get_study("rendering").settings(options)
    assert (rendering.seed, rendering.quality) == (7, "preview")
    assert get_study("reconstruction-error").settings(options) is False


def test_the_runner_writes_and_formats_what_the_study_computes(tmp_path):
    """Table 5.2 through the registry is the table computed directly, and its files exist."""
    done = run_study("reconstruction-error", tmp_path, StudyOptions(extension=False))
    assert done.text == format_table(reconstruction_table())
    assert done.paths and all(p.is_file() and p.parent == tmp_path for p in done.paths.values())
    assert not any(k.startswith("extended_") for k in done.paths)
