"""The float arithmetic that merges batches and lights, and composes a relighting, against
the float64 definitions it replaces (bit for bit) and independent of the number of threads."""

from __future__ import annotations

import numpy as np
import pytest

import spectrinsic.threads as threads
from spectrinsic.render.algebra.batch_means import batch_mean
from spectrinsic.render.algebra.light_transport import LightTransport, relit_result
from spectrinsic.render.algebra.shares import light_shares, sum_lights
from spectrinsic.scenes.model import Camera, Light, Scene


def _wide(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    """float32 values over 60 decades, both signs, with subnormals."""
    exponent = rng.uniform(-44, 15, shape)
    return (rng.choice([-1.0, 1.0], shape) * 10.0**exponent).astype(np.float32)


@pytest.mark.parametrize("n", [2, 3, 5])
def test_batch_mean_is_the_float64_mean_bit_for_bit(n):
    rng = np.random.default_rng(n)
    arrays = [_wide(rng, (64, 64, 7)) for _ in range(n)]
    expected = np.mean(np.stack(arrays), axis=0, dtype=np.float64).astype(np.float32)
    got = batch_mean(arrays)
    assert got.dtype == np.float32
    assert np.array_equal(got, expected, equal_nan=False)


def test_two_lights_sum_in_float32_equals_the_float64_sum_rounded():
    shares = _wide(np.random.default_rng(1), (4, 128, 128, 3))
    for chosen in ([0, 1], [3, 1], None):
        picked = shares[:2] if chosen is None else shares[chosen]
        expected = np.sum(picked, axis=0, dtype=np.float64).astype(np.float32)
        got = sum_lights(shares[:2] if chosen is None else shares, chosen)
        assert got.dtype == np.float32 and np.array_equal(got, expected)
    three = sum_lights(shares, [0, 1, 2])
    assert np.array_equal(three, np.sum(shares[:3], axis=0, dtype=np.float64).astype(np.float32))


def test_light_shares_are_within_one_float32_rounding_of_the_exact_product():
    rng = np.random.default_rng(2)
    parts = rng.random((2, 32, 32, 31), dtype=np.float32)
    emission = rng.uniform(1e-3, 1e3, (2, 31))
    got = light_shares(parts, emission)
    exact = parts.astype(np.float64) * emission[:, None, None, :]
    assert got.dtype == np.float32
    # two roundings (the value, the product) of 2**-24 each
    assert np.max(np.abs(got - exact) / exact) <= 2.0**-23


def test_thread_map_keeps_order_and_raises_the_tasks_error(monkeypatch):
    monkeypatch.setattr(threads, "array_threads", lambda: 3)
    assert threads.thread_map(lambda x: x * x, range(20)) == [x * x for x in range(20)]

    def fail(x: int) -> int:
        if x == 7:
            raise ValueError("task 7")
        return x

    with pytest.raises(ValueError, match="task 7"):
        threads.thread_map(fail, range(10))


def test_a_relighting_is_the_same_on_one_thread_and_on_several(monkeypatch):
    """The batches and modes compose side by side: the bits must not depend on it."""
    rng = np.random.default_rng(4)
    batches = tuple(
        {
            "rgb3": rng.random((2, 16, 16, 3), dtype=np.float32),
            "bands31": rng.random((2, 16, 16, 31), dtype=np.float32),
        }
        for _ in range(3)
    )
    transport = LightTransport(
        modes=("rgb3", "bands31"),
        sensors={"rgb3": "rgb3", "bands31": "bands:31@400-700"},
        batches=batches,
        seeds=(1, 2, 3),
        batch_spp=4,
        max_depth=3,
    )
    lights = (Light("point", "planck:3000K", 2.0), Light("point", "cie:D65", 0.5))
    scene = Scene("s", (), (), lights, Camera((0, 0, 1), (0, 0, 0)))
    results = []
    for n in (1, 4):
        monkeypatch.setattr(threads, "array_threads", lambda n=n: n)
        results.append(relit_result(transport, scene))
    one, many = results
    for mode in transport.modes:
        assert np.array_equal(one.images[mode], many.images[mode])
        assert np.array_equal(one.raw[mode], many.raw[mode])
        for a, b in zip(one.per_light, many.per_light):
            assert np.array_equal(a[mode], b[mode])
    assert not np.array_equal(one.raw["bands31"], batches[0]["bands31"].sum(axis=0))


def test_two_batches_whose_float32_sum_overflows_keep_the_float64_mean():
    big = np.full((4, 4), 3.0e38, np.float32)
    got = batch_mean([big, big])
    assert np.isfinite(got).all() and np.array_equal(got, big)


def test_light_shares_of_pixel_rows_equal_those_of_the_images():
    rng = np.random.default_rng(6)
    parts = rng.random((3, 8, 9, 6), dtype=np.float32)
    emission = rng.uniform(0.1, 10.0, (3, 6))
    rows = light_shares(parts.reshape(3, 72, 6), emission)
    assert np.array_equal(rows.reshape(parts.shape), light_shares(parts, emission))


def test_a_relit_image_is_the_sum_of_its_lights_and_the_xyz_of_its_raw_channels():
    """The image's XYZ is composed as the float64 sum of the lights' XYZ: it must equal the
    per-light images summed and the mode's matrix applied to the relit raw channels."""
    rng = np.random.default_rng(7)
    batches = tuple({"rgb6": rng.random((2, 24, 24, 6), dtype=np.float32)} for _ in range(2))
    transport = LightTransport(
        modes=("rgb6",),
        sensors={"rgb6": "gaussian:6@400-700"},
        batches=batches,
        seeds=(1, 2),
        batch_spp=4,
        max_depth=3,
    )
    lights = (Light("point", "planck:2700K", 2.0), Light("point", "cie:LED-RGB1", 0.7))
    scene = Scene("s", (), (), lights, Camera((0, 0, 1), (0, 0, 0)))
    result = relit_result(transport, scene)
    image = result.images["rgb6"].astype(np.float64)
    summed = sum(p["rgb6"].astype(np.float64) for p in result.per_light)
    matrix = np.asarray(result.meta["to_xyz"]["rgb6"])
    from_raw = result.raw["rgb6"].astype(np.float64) @ matrix.T
    scale = np.abs(image).max()
    assert np.abs(image - summed).max() <= 4e-7 * scale
    assert np.abs(image - from_raw).max() <= 4e-7 * scale


def test_an_owned_merge_is_merge_batches_bit_for_bit_and_reuses_the_first_batch(monkeypatch):
    """merge_owned_batches writes the mean over the first batch's transport (no third copy of
    a large render's transport), with merge_batches' bits: across blocks, in a block whose
    float32 sum overflows, and where an array is shared (images that are the raw channels,
    which batch_raw keeps, are not written over)."""
    import spectrinsic.render.algebra.batch_means as bm
    from spectrinsic.render.result import RenderResult

    monkeypatch.setattr(bm, "_HALF_BLOCK", 50)  # several blocks in a 6x7x3 transport

    def batch(seed: int) -> RenderResult:
        rng = np.random.default_rng(seed)
        transport = rng.lognormal(0.0, 3.0, (6, 7, 3)).astype(np.float32)
        transport[0, 0, 0] = np.float32(3e38)  # its block's float32 sum overflows
        image = rng.random((6, 7, 3)).astype(np.float32)
        timing = {"passes": 1, "seconds": 0.5, "per_pass": [0.5]}
        meta = {"spp": 3, "seed": seed, "timings": {"rgb3": timing}}
        return RenderResult(
            images={"rgb3": image}, raw={"rgb3": image}, transport={"rgb3": transport}, meta=meta
        )

    expected = bm.merge_batches([batch(1), batch(2)])
    first = batch(1)
    kept = first.raw["rgb3"].copy()
    merged = bm.merge_owned_batches([first, batch(2)])
    assert merged.transport["rgb3"] is first.transport["rgb3"]
    assert np.isfinite(merged.transport["rgb3"]).all()
    for field in ("transport", "images", "raw"):
        got, want = getattr(merged, field)["rgb3"], getattr(expected, field)["rgb3"]
        assert got.dtype == want.dtype and got.tobytes() == want.tobytes(), field
    assert merged.batch_raw[0]["rgb3"].tobytes() == kept.tobytes()
