"""Planning: the 68-sample layout, per-sample seeds and --only selection."""

from __future__ import annotations

import pytest

from spectrinsic.errors import SpectrinsicError
from spectrinsic.pipeline.presets import get_preset
from spectrinsic.pipeline.sample_plan import plan_samples
from spectrinsic.rng import seed_from_key

#: 8 objects x 4 conditions + 3 complex scenes x 3 views x 4 conditions (thesis section 5.2.4).
N_DEFAULT = 8 * 4 + 3 * 3 * 4


def test_plan_is_the_thesis_layout_with_recorded_seeds(tmp_path):
    cfg = get_preset("preview", seed=11)
    tasks = plan_samples(tmp_path, cfg)
    assert len(tasks) == N_DEFAULT == 68
    assert len({t.sample_id for t in tasks}) == N_DEFAULT
    assert sum(t.scene.startswith("obj-") for t in tasks) == 32
    for t in tasks:
        assert t.seed == seed_from_key(11, t.sample_id)
        assert t.out_dir == str(tmp_path) and t.config is cfg
    # seeds depend on the root seed
    other = plan_samples(tmp_path, get_preset("preview", seed=12))
    assert all(a.seed != b.seed for a, b in zip(tasks, other))


def test_only_selects_by_glob(tmp_path):
    cfg = get_preset("preview")
    tasks = plan_samples(tmp_path, cfg, only="obj-*__white, room-corner__v2__*")
    ids = {t.sample_id for t in tasks}
    assert len(ids) == 8 + 4
    assert all(i.endswith("__white") or i.startswith("room-corner__v2__") for i in ids)


def test_only_matching_nothing_is_an_error(tmp_path):
    with pytest.raises(SpectrinsicError, match="matches no sample"):
        plan_samples(tmp_path, get_preset("preview"), only="nothing-like-this")
