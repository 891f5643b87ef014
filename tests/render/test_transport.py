"""The per-light transport itself: what it depends on, and its batches."""

from __future__ import annotations

import dataclasses

import numpy as np

from spectrinsic.render import RenderSettings
from spectrinsic.render.transport_render import render_transport, render_transport_batches

SEED = 4
#: Two samples per pixel per batch.
SETTINGS = RenderSettings(spp=2, modes=("rgb3", "bands31"), max_depth=3)


def test_transport_does_not_depend_on_the_light_spectra_or_powers(make_room):
    """Each light emits the flat unit spectrum at power 1 in its transport, whatever the scene
    says: only geometry and materials enter, so two scenes differing in their lights alone give
    bit-identical transports (the same paths, the same values)."""
    scene = make_room(size=8)
    other = dataclasses.replace(
        scene,
        lights=tuple(
            dataclasses.replace(li, spectrum=s, power=7.0 * li.power)
            for li, s in zip(scene.lights, ("cie:LED-RGB1", "cie:FL11"), strict=True)
        ),
    )
    a, _ = render_transport(scene, SETTINGS, seed=SEED)
    b, _ = render_transport(other, SETTINGS, seed=SEED)
    assert set(a) == {"rgb3", "bands31"} and a["bands31"].shape == (2, 8, 8, 31)
    for mode in a:
        np.testing.assert_array_equal(a[mode], b[mode])
    # and each light is rendered alone: the two lights light the room differently
    assert not np.allclose(a["bands31"][0], a["bands31"][1], rtol=0.1)


def test_noise_target_adds_batches_to_the_transport_as_to_the_render(make_room):
    scene = make_room(size=8)
    transport, result = render_transport_batches(
        scene,
        SETTINGS.with_options(modes=("rgb3",), spp=4, batches=2, noise_target=1e-9, max_batches=3),
        seed=SEED,
    )
    assert len(transport.batches) == 3 and len(result.batch_raw) == 3
    assert transport.seeds == tuple(result.meta["batch_seeds"])
    assert result.meta["noise_target"]["max_batches"] == 3
    assert result.meta["spp"] == 3 * SETTINGS.batch_spp
    assert transport.batch_spp == SETTINGS.batch_spp
