"""The compact transport on disk (issue 45): the batches' float32 mean, float16 deviations for
the noise estimate, ZIP compression, parts only where the scene has them, and samples of the
per-batch layout written before it still load.

The independent references are the in-memory transport the renderer returned (the mean is
compared bit for bit with :func:`batch_mean` of its batches) and a file written in the old
per-batch layout by this test itself.
"""

from __future__ import annotations

import numpy as np
import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export.formats.exr import read_exr, read_exr_attributes, write_exr
from spectrinsic.gt_export.sample.meta import read_meta
from spectrinsic.gt_export.sample.transport_exr import (
    COMPACT_LAYOUT,
    COVERAGE_LAYER,
    TRANSPORT_NAME,
    read_transport,
    transport_layer,
)
from spectrinsic.render import RenderSettings
from spectrinsic.render.algebra.batch_means import batch_mean
from spectrinsic.spectra import get_sensors
from tests.gt_export._builders import render_transport_sample

pytestmark = pytest.mark.render

SETTINGS = RenderSettings(spp=4, modes=("rgb3", "bands31"), batches=2, max_depth=3)
SEED = 5


@pytest.fixture(scope="module")
def matte(tmp_path_factory, make_room):
    """A matte two-light room's transport, in memory and written as a sample."""
    out = tmp_path_factory.mktemp("compact")
    scene = make_room(size=12)
    sample, transport, _ = render_transport_sample(
        out, scene, SETTINGS, seed=SEED, sample_id="room__v0__compact", config={"test": "compact"}
    )
    return transport, sample


def test_a_matte_scene_stores_no_glossy_part_and_a_compressed_compact_file(matte):
    transport, sample = matte
    record = read_meta(sample).raw["transport"]
    assert record["layout"] == COMPACT_LAYOUT and record["parts"] == []
    header = read_exr_attributes(sample / TRANSPORT_NAME)
    names = {str(getattr(c, "name", c)) for c in header["channels"]}  # type: ignore[union-attr]
    assert not any(n.startswith(("S", "W")) for n in names)
    assert "ZIPS" in str(header["compression"]).upper()
    # one mean per light and mode, one deviation per light and mode for the first batch
    assert {n.split(".")[0] for n in names} == {COVERAGE_LAYER} | {
        f"{p}{j}{b}_{m}"
        for j in range(transport.n_lights)
        for m in transport.modes
        for p, b in (("L", ""), ("D", "_b0"))
    }


def test_the_mean_is_exact_and_the_batches_keep_half_precision_deviations(matte):
    transport, sample = matte
    read, _ = read_transport(sample, read_meta(sample).raw["transport"])
    stored = read_exr(sample / TRANSPORT_NAME)
    for mode in transport.modes:
        batches = [b[mode] for b in transport.batches]
        mean = batch_mean(batches)
        for j in range(transport.n_lights):  # the stored mean: bit for bit
            np.testing.assert_array_equal(stored[transport_layer(j, None, mode)], mean[j])
        again = batch_mean([b[mode] for b in read.batches])  # to float32 rounding
        np.testing.assert_allclose(again, mean, rtol=0, atol=1e-6 * float(np.abs(mean).max()))
        for got, want in zip(read.batches, batches):
            spread = float(np.abs(want - mean).max())
            # float16: 11 significant bits of the largest deviation, plus float32 rounding
            bound = 2.0**-11 * spread + 1e-6 * float(np.abs(mean).max())
            assert float(np.abs(got[mode] - want).max()) <= bound, mode


def test_a_sample_of_the_per_batch_layout_still_loads(matte, tmp_path):
    transport, sample = matte
    record = read_meta(sample).raw["transport"]
    coverage = read_transport(sample, record)[1]
    layers: dict[str, np.ndarray] = {COVERAGE_LAYER: coverage}
    names: dict[str, tuple[str, ...]] = {
        COVERAGE_LAYER: tuple(f"m{m}" for m in range(coverage.shape[-1]))
    }
    for b, batch in enumerate(transport.batches):  # the layout before issue 45, as it was written
        for mode in transport.modes:
            for j in range(transport.n_lights):
                layers[transport_layer(j, b, mode)] = batch[mode][j]
                names[transport_layer(j, b, mode)] = get_sensors(transport.sensors[mode]).channels
    write_exr(tmp_path / TRANSPORT_NAME, layers, channel_names=names, compression="none")
    old = {k: v for k, v in record.items() if k not in ("layout", "deviation_exponents")}
    read, _ = read_transport(tmp_path, old)
    for got, want in zip(read.batches, transport.batches):
        for mode in transport.modes:
            np.testing.assert_array_equal(got[mode], want[mode])


def test_an_unknown_layout_is_refused_in_one_line(matte):
    _, sample = matte
    record = {**read_meta(sample).raw["transport"], "layout": "future-v9"}
    with pytest.raises(DatasetError, match="layout 'future-v9' is unknown") as error:
        read_transport(sample, record)
    assert "\n" not in str(error.value)


def test_half_layers_are_written_only_where_named(tmp_path):
    deviation = np.linspace(-2, 2, 12, dtype=np.float16).reshape(3, 4)
    path = write_exr(tmp_path / "h.exr", {"d": deviation}, half=("d",), compression="zips")
    np.testing.assert_array_equal(read_exr(path)["d"], deviation.astype(np.float32))
    with pytest.raises(DatasetError, match="float16; ground truth is stored as float32"):
        write_exr(tmp_path / "g.exr", {"d": deviation})
    with pytest.raises(DatasetError, match="a half layer must be finite float16"):
        write_exr(tmp_path / "g.exr", {"d": deviation.astype(np.float32)}, half=("d",))
    with pytest.raises(DatasetError, match="EXR compression 'b44'"):
        write_exr(tmp_path / "g.exr", {"d": deviation.astype(np.float32)}, compression="b44")
    assert not (tmp_path / "g.exr").exists()
