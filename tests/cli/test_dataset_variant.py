"""``dataset --variant`` (issue 31): the backend is recorded in the config, an unknown one is
refused before any work, and ``render --ground-truth --variant`` passes it on."""

from __future__ import annotations

from spectrinsic.cli import build_parser, main
from spectrinsic.cli.dataset import config_from_args


def test_the_variant_is_recorded_in_the_config():
    args = build_parser().parse_args(["dataset", "--variant", "scalar", "--out", "x"])
    config = config_from_args(args)
    assert config.render.variant == "scalar" and config.settings()["variant"] == "scalar"
    plain = config_from_args(build_parser().parse_args(["dataset", "--out", "x"]))
    assert plain.render.variant is None


def test_an_unknown_backend_is_refused_before_any_work(tmp_path, capsys):
    out = tmp_path / "set"
    assert main(["dataset", "--variant", "cudaa", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "did you mean 'cuda'" in err
    assert not out.exists()
