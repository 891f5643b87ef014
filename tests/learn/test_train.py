"""``spectrinsic train`` on the tiny synthetic set: outputs, determinism, resume, refusals."""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import pytest

from spectrinsic.cli import main
from spectrinsic.errors import DatasetError
from spectrinsic.learn.train import CHECKPOINT, TrainOptions, train

pytestmark = pytest.mark.torch

#: Steps of the short runs: enough to move every weight, a second or two on one thread.
STEPS = 4


def _train(tiny_set: Path, out: Path, *extra: str) -> int:
    return main(["-q", "train", str(tiny_set), "--out", str(out), "--batch", "2", *extra])


def _weights(torch, folder: Path) -> dict:
    return torch.load(folder / "weights.pt", weights_only=True)["state_dict"]


def _same(a: dict, b: dict, torch) -> bool:
    return a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a)


def test_train_writes_weights_curve_and_card(tiny_set, tmp_path, torch):
    out = tmp_path / "run"
    assert _train(tiny_set, out, "--steps", str(STEPS)) == 0
    for name in ("weights.pt", "curve.csv", "curve.png", "MODEL.md", "model.json"):
        assert (out / name).stat().st_size > 0, name
    with (out / "curve.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [int(r["step"]) for r in rows] == list(range(1, STEPS + 1))
    assert all(float(r["loss"]) > 0 for r in rows)  # Eq. 4 with λ < 1 is positive unless exact
    card = json.loads((out / "model.json").read_text())
    # the train split of the tiny set (splits by scene, manifest.json)
    train_ids = json.loads((tiny_set / "manifest.json").read_text())["splits"]["train"]
    assert card["sample_ids"] == sorted(train_ids) and card["samples"] == len(train_ids)
    assert len(card["config_hashes"]) == 1 and card["options"]["steps"] == STEPS
    assert "Eigen" in (out / "MODEL.md").read_text()


def test_one_seed_gives_identical_weights(tiny_set, tmp_path, torch):
    runs = {}
    for name, seed in (("a", "0"), ("b", "0"), ("c", "1")):
        assert _train(tiny_set, tmp_path / name, "--steps", str(STEPS), "--seed", seed) == 0
        runs[name] = _weights(torch, tmp_path / name)
    assert _same(runs["a"], runs["b"], torch)
    assert not _same(runs["a"], runs["c"], torch)  # the seed matters, so equality means something


def test_resume_continues_a_killed_run(tiny_set, tmp_path, torch):
    options = TrainOptions(steps=2 * STEPS, batch=2, checkpoint_every=STEPS)
    straight = train(tiny_set, _mkdir(tmp_path / "straight"), options)

    killed = _mkdir(tmp_path / "killed")

    def kill(step: int, loss: float) -> None:
        if step == STEPS + 2:  # past the checkpoint of step STEPS, before the next
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        train(tiny_set, killed, options, on_step=kill)
    assert torch.load(killed / CHECKPOINT, weights_only=False)["step"] == STEPS
    resumed = train(tiny_set, killed, options, resume=True)
    assert resumed.resumed_from == STEPS
    assert _same(straight.state_dict, resumed.state_dict, torch)
    assert resumed.curve == straight.curve


def test_cli_resume_to_more_steps_equals_a_straight_run(tiny_set, tmp_path, torch):
    assert _train(tiny_set, tmp_path / "s", "--steps", str(2 * STEPS)) == 0
    assert _train(tiny_set, tmp_path / "r", "--steps", str(STEPS)) == 0
    assert _train(tiny_set, tmp_path / "r", "--steps", str(2 * STEPS), "--resume") == 0
    assert _same(_weights(torch, tmp_path / "s"), _weights(torch, tmp_path / "r"), torch)
    card = json.loads((tmp_path / "r" / "model.json").read_text())
    assert card["resumed_from"] == STEPS and card["steps_this_run"] == STEPS


def _mkdir(path: Path) -> Path:
    path.mkdir()
    return path


def test_refusals_are_one_line(tiny_set, tmp_path, capsys, torch, monkeypatch):
    out = tmp_path / "x"
    assert _train(tiny_set, out, "--layers", "image_rgb3,reflectance,shading") == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "image_rgb3" in err and "needs the layers" in err
    assert not out.exists()  # refused before any folder was made
    assert _train(tiny_set, out, "--relight") == 2  # the tiny set stores no transport
    assert "--store-transport" in capsys.readouterr().err
    if not torch.cuda.is_available():
        assert _train(tiny_set, out, "--device", "cuda") == 2
        assert "no CUDA device" in capsys.readouterr().err
    assert not out.exists()
    assert _train(tiny_set, out, "--steps", "1") == 0
    assert _train(tiny_set, out, "--steps", "1") == 2  # a checkpoint without --resume
    assert "--resume" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "torch", None)  # import torch now raises ImportError
    assert _train(tiny_set, tmp_path / "y") == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "spectrinsic[torch]" in err


def test_a_crop_smaller_than_the_unit_is_refused(tiny_set, tmp_path, torch):
    from spectrinsic.learn.unet import UNetConfig

    with pytest.raises(DatasetError, match="unit"):
        train(tiny_set, tmp_path, TrainOptions(steps=1, net=UNetConfig(levels=4)))
