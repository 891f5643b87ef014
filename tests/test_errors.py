"""validate_choice raises the caller's domain error; every package passes its own."""

from __future__ import annotations

import pytest

from spectrinsic.errors import (
    DatasetError,
    DecomposeError,
    RenderError,
    SceneError,
    SpectrinsicError,
    SpectrumNotFoundError,
    validate_choice,
)


def test_validate_choice_raises_the_given_domain_error():
    assert validate_choice("b", ["a", "b"], "letter", error=SceneError) == "b"
    with pytest.raises(SceneError, match=r"unknown letter 'c'; expected one of 'a', 'b'"):
        validate_choice("c", ["a", "b"], "letter", error=SceneError)
    with pytest.raises(SpectrinsicError) as info:
        validate_choice("c", ["a", "b"], "letter")
    assert type(info.value) is SpectrinsicError  # the default stays the base class


def _calls():
    """(id, call, error): an unknown name given to each package's validated choices."""
    import numpy as np

    from spectrinsic.decompose.methods.constancy import illuminant_colour
    from spectrinsic.decompose.metrics import get_metric
    from spectrinsic.pipeline.executors import make_executor
    from spectrinsic.pipeline.presets import get_preset
    from spectrinsic.render.algebra.modes import get_mode
    from spectrinsic.render.base.variants import choose_variant
    from spectrinsic.scenes.generators import generated_scene_name
    from spectrinsic.spectra import illuminant_set

    image, mask = np.ones((2, 2, 3)), np.ones((2, 2), bool)
    return [
        ("illuminant set", lambda: illuminant_set("planckan"), SpectrumNotFoundError),
        ("generator", lambda: generated_scene_name("roms", 0), SceneError),
        ("render mode", lambda: get_mode("rgb4"), RenderError),
        ("variant kind", lambda: choose_variant("rgbb"), RenderError),  # type: ignore[arg-type]
        ("executor", lambda: make_executor("proces"), DatasetError),
        ("preset", lambda: get_preset("previw"), DatasetError),
        ("metric", lambda: get_metric("lmes"), DecomposeError),
        ("constancy", lambda: illuminant_colour(image, mask, "grey"), DecomposeError),
    ]


@pytest.mark.parametrize(
    ("what", "call", "error"), _calls(), ids=lambda x: x if isinstance(x, str) else ""
)
def test_unknown_names_raise_their_packages_error(what, call, error):
    with pytest.raises(error, match="unknown"):
        call()
