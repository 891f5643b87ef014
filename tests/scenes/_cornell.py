"""The walls of the Mitsuba XML Cornell boxes the tests write (tests/scenes/test_mitsuba_xml.py,
tests/render/_reference.py): one home for the five rectangles, so each box differs only by what
it says.

A helper module, not a conftest: its function takes arguments, and tests/test_test_layout.py
checks only ``test_*.py`` files.
"""

from __future__ import annotations

__all__ = ["box_walls"]

_WALLS = """  <shape type="rectangle" id="floor"><ref id="{floor}"/></shape>
  <shape type="rectangle" id="ceiling"><ref id="white"/>
    <transform name="to_world"><rotate x="1" angle="180"/><translate value="0 0 2"/></transform>
  </shape>
{before_back}  <shape type="rectangle" id="back"><ref id="white"/>
    <transform name="to_world"><rotate x="1" angle="90"/><translate value="0 1 1"/></transform>
  </shape>
  <shape type="rectangle" id="left"><ref id="{left}"/>
    <transform name="to_world"><rotate y="1" angle="90"/><translate value="-1 0 1"/></transform>
  </shape>
  <shape type="rectangle" id="right"><ref id="green"/>
    <transform name="to_world"><rotate y="1" angle="-90"/><translate value="1 0 1"/></transform>
  </shape>"""


def box_walls(*, floor: str = "white", left: str = "red", before_back: str = "") -> str:
    """XML lines of a 2 × 2 × 2 room's five walls, Mitsuba ``rectangle`` shapes (2 × 2 at the
    origin, facing +z) turned and moved into place: ``floor`` (z = 0, of BSDF id *floor*),
    ``ceiling`` (z = 2), ``back`` (y = 1), ``left`` (x = −1, of *left*) and ``right`` (x = 1,
    of ``green``); ceiling and back ``white``. The room is open towards −y. *before_back*:
    lines (a shape before the back wall) placed after the ceiling."""
    return _WALLS.format(floor=floor, left=left, before_back=before_back)
