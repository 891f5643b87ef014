"""The sample split of a render (spectrinsic/render/base/sample_split.py): its parts, and a
render's bits independent of Dr.Jit's thread count.

A 32 x 32 Cornell box at 160 spp is 163,840 lanes: Dr.Jit cuts it into work units of 16,384
lanes, whose borders fall inside pixels (16,384 / 160 is not whole), so an unsplit render added
the samples of those pixels from two threads in an order that followed the schedule. Split,
its 128-spp part keeps whole pixels per unit and its 32-spp part (32,768 lanes, cut into one
share per thread) runs on one thread.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.render.base.sample_split import (
    WORK_UNIT,
    part_seeds,
    sample_splits,
    single_thread,
    split_render,
)
from spectrinsic.render.base.variants import choose_variant, usable_backends, variant_scope

SIZE = 32


@pytest.mark.parametrize(
    "spp", [1, 2, 3, 5, 96, 160, 320, 1000, 4096, WORK_UNIT, 3 * WORK_UNIT + 7]
)
def test_splits_are_powers_of_two_summing_to_spp(spp):
    parts = sample_splits(spp)
    assert sum(parts) == spp
    assert all(p & (p - 1) == 0 and 1 <= p <= WORK_UNIT for p in parts)
    assert list(parts) == sorted(parts, reverse=True)
    assert len(parts) == spp // WORK_UNIT + bin(spp % WORK_UNIT).count("1")


@pytest.mark.parametrize("spp", [0, -4, 2.5, True])
def test_splits_refuse_a_count_that_is_not_positive(spp):
    with pytest.raises(ValueError, match="samples per pixel"):
        sample_splits(spp)


def test_part_seeds_start_with_the_seed_and_differ():
    seeds = part_seeds(11, 4)
    assert seeds[0] == 11 and len(set(seeds)) == 4
    assert part_seeds(11, 4) == seeds  # a function of the seed alone
    assert part_seeds(12, 4)[1:] != seeds[1:]


def test_single_thread_below_two_work_units_per_thread():
    assert single_thread(2 * WORK_UNIT * 4, 4)
    assert not single_thread(2 * WORK_UNIT * 4 + 1, 4)
    assert not single_thread(10, 1)  # already one thread


@pytest.fixture(scope="module")
def llvm():
    if "llvm" not in usable_backends():
        pytest.skip("Dr.Jit's LLVM backend is not usable here: the split applies to it alone")
    with variant_scope(choose_variant("rgb", "llvm")) as mi:
        import drjit

        scene = mi.cornell_box()
        scene["sensor"]["film"].update(width=SIZE, height=SIZE, rfilter={"type": "box"})
        before = drjit.thread_count()
        yield mi, mi.load_dict(scene), drjit
        drjit.set_thread_count(before)


def test_a_render_is_the_same_bits_for_any_thread_count(llvm):
    mi, scene, drjit = llvm
    images = {}
    for threads in (2, 1, 3, 2):
        drjit.set_thread_count(threads)
        for spp in (160, 64):
            image = split_render(mi, scene, spp=spp, seed=5)
            images.setdefault(spp, []).append(image)
    for spp, runs in images.items():
        assert runs[0].shape == (SIZE, SIZE, 3) and runs[0].max() > 0
        for run in runs[1:]:
            np.testing.assert_array_equal(run, runs[0], err_msg=f"{spp} spp")


def test_a_split_render_is_the_sample_weighted_mean_of_its_parts(llvm):
    mi, scene, _ = llvm

    def plain(spp: int, seed: int) -> np.ndarray:
        return np.array(mi.render(scene, spp=spp, seed=seed), np.float64)

    np.testing.assert_array_equal(split_render(mi, scene, spp=64, seed=5), plain(64, 5))
    seeds = part_seeds(5, 2)
    mean = (128 * plain(128, seeds[0]) + 32 * plain(32, seeds[1])) / 160
    np.testing.assert_array_equal(split_render(mi, scene, spp=160, seed=5), mean.astype(np.float32))
