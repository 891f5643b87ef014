"""``spectrinsic list`` and ``--version`` (issue 19: a CLI that lists what it knows)."""

from __future__ import annotations

from importlib.metadata import version

import pytest

from spectrinsic.cli import main


def _listed(capsys, *argv: str) -> list[str]:
    assert main(["list", *argv]) == 0
    return [line.split("  ")[0] for line in capsys.readouterr().out.splitlines()]


def test_version_is_the_installed_distribution(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.strip() == f"spectrinsic {version('spectrinsic')}"


def test_help_names_the_list_verb(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    assert "list" in capsys.readouterr().out


def test_each_listing_is_its_registry(capsys):
    from spectrinsic.decompose import available_decomposers
    from spectrinsic.pipeline.presets import PRESETS
    from spectrinsic.scenes import CONDITIONS, scene_names
    from spectrinsic.scenes.generators import GENERATORS
    from spectrinsic.spectra.registry import SPECTRUM_FAMILIES

    assert _listed(capsys, "scenes") == scene_names() + scene_names("glossy")
    assert _listed(capsys, "conditions") == list(CONDITIONS)
    assert _listed(capsys, "presets") == list(PRESETS)
    assert _listed(capsys, "methods") == list(available_decomposers())
    assert _listed(capsys, "generators") == list(GENERATORS)
    assert _listed(capsys, "spectra") == list(SPECTRUM_FAMILIES)
    assert len(_listed(capsys, "spectra", "munsell")) == 1269  # luxpy's matte Munsell set
    assert "camera:Nikon 5100 (NPL)" in _listed(capsys, "cameras")  # shipped by colour-science


def test_descriptions_come_with_the_names(capsys):
    from spectrinsic.pipeline.presets import PRESETS

    assert main(["list", "presets"]) == 0
    out = dict(line.split(None, 1) for line in capsys.readouterr().out.splitlines())
    for name, cfg in PRESETS.items():
        assert out[name].startswith(f"{cfg.width}×{cfg.height}, ")
    assert main(["list", "methods"]) == 0
    assert "Grosse et al. 2009" in capsys.readouterr().out  # not cut at "et al."


def test_every_condition_and_family_has_a_description_whose_example_resolves():
    from spectrinsic.scenes.library import CONDITION_DESCRIPTIONS, CONDITIONS
    from spectrinsic.spectra import get_spectrum
    from spectrinsic.spectra.registry import SPECTRUM_FAMILIES, SPECTRUM_FAMILY_NOTES

    assert list(CONDITION_DESCRIPTIONS) == list(CONDITIONS)
    assert list(SPECTRUM_FAMILY_NOTES) == list(SPECTRUM_FAMILIES)
    for family, note in SPECTRUM_FAMILY_NOTES.items():
        example = note.split(";")[0].split(", ")[0].split(" or ")[0]
        assert example.startswith(f"{family}:"), note
        # the SFU families need the data directory, csv a file of the user's
        if not family.startswith("sfu") and family != "csv":
            assert get_spectrum(example).name


def test_a_family_that_cannot_be_listed_is_one_line(capsys):
    assert main(["list", "spectra", "planck"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "'planck'" in err and "munsell" in err
    assert main(["list", "scenes", "munsell"]) == 2
    assert "only 'list spectra' takes a FAMILY" in capsys.readouterr().err


def test_the_data_directory_families_examples_resolve(data_dir):
    from spectrinsic.spectra import get_spectrum
    from spectrinsic.spectra.registry import SPECTRUM_FAMILY_NOTES

    for family in ("sfu", "sfu-illum"):
        example = SPECTRUM_FAMILY_NOTES[family].split(";")[0]
        assert get_spectrum(example, data_dir=data_dir).name == example


def test_camera_presets_are_listed_under_their_one_name(capsys):
    """Issue 47: ``list cameras`` names the --camera presets first, each named by the slug of
    its sensor set, the name of its files (``sensor-<slug>.*``); the old name still works."""
    from spectrinsic.gt_export.formats.names import camera_slug
    from spectrinsic.spectra.camera_model import CAMERA_PRESETS, PRESET_ALIASES, camera_model

    listed = _listed(capsys, "cameras")
    assert listed[: len(CAMERA_PRESETS)] == list(CAMERA_PRESETS)
    for name, model in CAMERA_PRESETS.items():
        assert camera_slug(model.sensitivities) == name
    for old, new in PRESET_ALIASES.items():
        assert camera_model(old) is CAMERA_PRESETS[new]
