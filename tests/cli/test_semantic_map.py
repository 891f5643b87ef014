"""``--semantic-map FILE`` (issue 41) from the command line: it reaches the sample's
``semantic`` layer through a render, is recorded in the build's config, and bad maps or
options that do not apply are refused in one line with exit status 2 before any work."""

from __future__ import annotations

import json

import numpy as np
import pytest

from spectrinsic.cli import main
from spectrinsic.gt_export import load_sample
from spectrinsic.gt_export.sample import sample_dirs
from spectrinsic.scenes.semantic import class_id
from tests.conftest import QUAD_YAML


def test_a_user_map_labels_the_rendered_semantic_layer(tmp_path, capsys):
    scene = tmp_path / "quad.yaml"
    scene.write_text(QUAD_YAML)  # one mesh, "ground": a floor by the default map
    rules = tmp_path / "map.yaml"
    rules.write_text('rules: {"^ground$": unlabelled}\n')
    out = tmp_path / "out"
    argv = ["-q", "render", str(scene), "--ground-truth", "--semantic-map", str(rules)]
    rc = main([*argv, "--out", str(out), "--preset", "preview", "--spp", "2"])
    assert rc == 0, capsys.readouterr().err
    (folder,) = sample_dirs(out)
    sample = load_sample(folder)
    semantic, object_id = sample["semantic"], sample["ids"]["object"]
    assert (semantic == class_id("unlabelled")).any()
    np.testing.assert_array_equal(semantic >= 0, object_id >= 0)  # one object, one class
    assert set(np.unique(semantic)) <= {-1, class_id("unlabelled")}
    source = json.loads(json.loads((out / "manifest.json").read_text())["config"]["source"])
    assert source["semantic_map"] == {"rules": [["^ground$", "unlabelled"]], "fallback": None}


@pytest.mark.parametrize(
    "argv, expected",
    [
        (["render", "SCENE", "--ground-truth", "--semantic-map", "MAP"], "class 'tabel'"),
        (["render", "SCENE", "--semantic-map", "MAP"], "applies only with --ground-truth"),
        (["dataset", "--scenes", "SCENE", "--semantic-map", "MAP"], "--semantic-map: "),
        (["render", "obj-apple", "--semantic-map", "MAP"], "--semantic-map applies to scene files"),
        (["dataset", "--generator", "rooms", "--semantic-map", "MAP"], "--semantic-map"),
    ],
)
def test_a_bad_or_misplaced_map_is_one_line_rc2(tmp_path, capsys, argv, expected):
    scene, rules = tmp_path / "quad.yaml", tmp_path / "map.yaml"
    scene.write_text(QUAD_YAML)
    rules.write_text('rules: {"desk": tabel}\n')
    names = {"SCENE": str(scene), "MAP": str(rules)}
    rc = main(["-q", *(names.get(a, a) for a in argv), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert expected in err, err
    assert not (tmp_path / "o").exists()
