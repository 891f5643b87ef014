"""The notes of a scene file's read: one line per phrase, each naming the file once, whatever
the reader (a Mitsuba XML file, a ``.blend``) and without the reader's name."""

from __future__ import annotations

from spectrinsic.scenes.model import Camera, Scene
from spectrinsic.scenes.reading_notes import reading_notes

CAMERA = Camera(origin=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0))


def _scene(**metadata: object) -> Scene:
    return Scene("room", (), (), (), CAMERA, dict(metadata))


def test_a_blend_note_names_the_file_not_the_reader():
    scene = _scene(source="blender", file="room.blend", approximated=["world 'W': a mix: left out"])
    assert reading_notes(scene) == ["room.blend: approximated: world 'W': a mix: left out"]


def test_an_xml_note_names_the_file_and_its_version_in_kind_order():
    scene = _scene(
        source="room.xml (Mitsuba XML 0.6.0)",
        ignored=["rfilter gaussian"],
        approximated=["emitter 'sun': left out"],
        fixed=["ext_eta -> ext_ior"],
    )
    assert reading_notes(scene) == [
        "room.xml (Mitsuba XML 0.6.0): fixed: ext_eta -> ext_ior",
        "room.xml (Mitsuba XML 0.6.0): approximated: emitter 'sun': left out",
        "room.xml (Mitsuba XML 0.6.0): ignored: rfilter gaussian",
    ]


def test_a_scene_read_without_notes_has_none():
    assert reading_notes(_scene()) == [] and reading_notes(_scene(file="a.blend")) == []
