"""The ``spectrinsic.decomposers`` entry-point group adds methods to the registry and tables."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from spectrinsic.decompose.evaluation.evaluate import evaluate
from spectrinsic.decompose.methods.registry import (
    DECOMPOSERS,
    ENTRY_POINT_GROUP,
    PluginError,
    available_decomposers,
    get_decomposer,
)
from spectrinsic.decompose.report import write_report
from tests.decompose.evaluation.test_evaluate import _sample

TOY_MODULE = '''
from dataclasses import dataclass

import numpy as np

from spectrinsic.decompose.decomposition import finish, prepare_input


@dataclass(frozen=True)
class HalfImage:
    """Reflectance = image / 2 (so shading = 2 everywhere)."""

    name: str = "toy-half"

    def __call__(self, image, mask=None):
        img, m = prepare_input(image, mask)
        return finish(img, img / 2.0, m, {"toy": True})


NOT_A_FACTORY = 42
'''


def _install_dist(root, entries: dict[str, str]) -> None:
    """A minimal installed distribution: a module and a dist-info with entry_points.txt."""
    (root / "toy_spectrinsic_plugin.py").write_text(TOY_MODULE)
    info = root / "toy_spectrinsic_plugin-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: toy-spectrinsic-plugin\nVersion: 0.1\n"
    )
    lines = "\n".join(f"{k} = {v}" for k, v in entries.items())
    (info / "entry_points.txt").write_text(f"[{ENTRY_POINT_GROUP}]\n{lines}\n")


@pytest.fixture()
def plugin_dir(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    return tmp_path


def test_entry_point_adds_a_method_to_the_registry_and_the_tables(plugin_dir, tmp_path):
    _install_dist(plugin_dir, {"toy-half": "toy_spectrinsic_plugin:HalfImage"})
    assert "toy-half" not in DECOMPOSERS
    assert list(available_decomposers())[: len(DECOMPOSERS)] == list(DECOMPOSERS)
    assert "toy-half" in available_decomposers()
    toy = get_decomposer("toy-half")
    image = np.full((4, 4, 3), 0.8)
    np.testing.assert_allclose(toy(image).reflectance, 0.4, rtol=1e-6)

    samples = [_sample("obj-a__v0__white", 0, (1, 1, 1), False)]
    out = tmp_path / "evaluation"
    run = evaluate(
        samples,
        out,
        methods=["image-as-reflectance", "toy-half"],
        seed=0,
        cameras=False,
        figures=False,
        save_estimates=False,
    )
    write_report(out, run)
    rows = {r["method"]: r for r in csv.DictReader((out / "lmse_by_condition.csv").open())}
    assert set(rows) == {"image-as-reflectance", "toy-half"}
    # image / 2 is the image up to scale: every scale-invariant score equals the baseline's
    assert float(rows["toy-half"]["reflectance_WL"]) == pytest.approx(
        float(rows["image-as-reflectance"]["reflectance_WL"]), rel=1e-9
    )
    assert "toy-half" in (out / "REPORT.md").read_text()


def test_cli_lists_plugins_by_default(plugin_dir):
    _install_dist(plugin_dir, {"toy-half": "toy_spectrinsic_plugin:HalfImage"})
    from spectrinsic.cli import build_parser
    from spectrinsic.cli.evaluate import _methods

    methods = _methods(build_parser().parse_args(["evaluate"]))
    assert list(methods) == [*DECOMPOSERS, "toy-half"]


@pytest.mark.parametrize(
    ("entries", "match"),
    [
        ({"toy-bad": "toy_spectrinsic_plugin:NOT_A_FACTORY"}, "must load a callable factory"),
        ({"toy-gone": "toy_spectrinsic_plugin:Missing"}, "cannot be loaded: AttributeError"),
        ({"colour-retinex": "toy_spectrinsic_plugin:HalfImage"}, "reuses the name"),
    ],
)
def test_bad_entry_points_are_one_line_errors(plugin_dir, entries, match):
    _install_dist(plugin_dir, entries)
    with pytest.raises(PluginError, match=match):
        available_decomposers()
