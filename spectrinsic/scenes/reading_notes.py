"""What reading a scene file changed, as lines for stderr: the fixes of an old Mitsuba XML file,
the approximations that ``--approximate`` made (a Mitsuba XML file's, a ``.blend``'s World) and
the settings it ignored.

The readers record each as one phrase in ``scene.metadata["fixed"]``, ``["approximated"]`` and
``["ignored"]``, naming the part of the file (an element, a World) but not the file;
:func:`reading_notes` prefixes each with the file it came from.
"""

from __future__ import annotations

from .model import Scene

__all__ = ["NOTE_KINDS", "reading_notes"]

#: The kinds of note, in the order they are said (each a list of phrases in the metadata).
NOTE_KINDS = ("fixed", "approximated", "ignored")


def _origin(scene: Scene) -> str:
    """The file *scene* was read from: a ``.blend``'s ``"file"``, a Mitsuba XML file's
    ``"source"`` (``"NAME (Mitsuba XML VERSION)"``), else the scene's name."""
    meta = scene.metadata
    return str(meta.get("file") or meta.get("source") or scene.name)


def reading_notes(scene: Scene) -> list[str]:
    """One line ``"<file>: <kind>: <phrase>"`` per fix, approximation and ignored setting of
    *scene*'s read (:data:`NOTE_KINDS`; empty for a scene read without any), for example
    ``room.blend: approximated: world 'World': its Surface comes from Mix Shader node 'Mix':
    left out``."""
    origin = _origin(scene)
    return [
        f"{origin}: {kind}: {phrase}"
        for kind in NOTE_KINDS
        for phrase in scene.metadata.get(kind, ())
    ]
