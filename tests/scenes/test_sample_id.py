"""The sample id: one record, one text form, one parser."""

from __future__ import annotations

import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.scenes import SampleId, default_samples


@pytest.mark.parametrize(
    "text, parts",
    [
        ("obj-vase__v0__two-colour-a", ("obj-vase", 0, "two-colour-a")),
        ("objects-on-ground-00001__v12__white", ("objects-on-ground-00001", 12, "white")),
        ("my__scene__v0__file", ("my__scene", 0, "file")),  # a scene file's stem may hold __
    ],
)
def test_parse_and_str_round_trip(text, parts):
    sid = SampleId.parse(text)
    assert (sid.scene, sid.view, sid.condition) == parts
    assert str(sid) == text
    assert SampleId.parse(str(SampleId(*parts))) == SampleId(*parts)


def test_every_library_sample_round_trips():
    samples = default_samples()
    assert [SampleId.parse(str(s)) for s in samples] == samples


@pytest.mark.parametrize(
    "bad",
    [
        "obj-vase",
        "obj-vase__white",
        "obj-vase__vx__white",
        "obj-vase__v0__",
        "__v0__white",
        "obj-vase__v0__white__extra",
    ],
)
def test_parse_names_the_bad_id(bad):
    with pytest.raises(DatasetError, match=f"sample id {bad!r} is not of the form"):
        SampleId.parse(bad)


def test_sample_id_is_a_frozen_record():
    sid = SampleId("obj-vase", 0, "white")
    with pytest.raises(AttributeError):
        sid.view = 1  # type: ignore[misc]
    assert sid == SampleId("obj-vase", 0, "white") and hash(sid) == hash(
        SampleId("obj-vase", 0, "white")
    )
