"""A scene's problems as one line: ``"<source>: <field>: <problem>"``, several collected into one.

The checks of :mod:`spectrinsic.scenes.validate` and :mod:`spectrinsic.scenes.placement`, and the
YAML reader, report through these, so a scene with several faults is told all of them at once.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

from ..errors import SceneError

__all__ = ["Problems", "field_error"]

T = TypeVar("T")


class Problems:
    """Collects the errors of a scene's independent parts, so one run reports all of them.

    Each part runs through :meth:`get`; a :class:`SceneError` there is recorded and ``None``
    returned. :meth:`raise_if_any` then raises one one-line error listing every problem.
    """

    def __init__(self, source: str) -> None:
        self.source = source
        self.messages: list[str] = []

    def get(self, fn: Callable[..., T], *args: object) -> T | None:
        """``fn(*args)``, or ``None`` after recording its SceneError."""
        try:
            return fn(*args)
        except SceneError as exc:
            message = str(exc)
            self.messages.append(message.removeprefix(f"{self.source}: "))
            return None

    def raise_if_any(self) -> None:
        """Raise ``"<source>: <problem>"``, or ``"<source>: N problems: a; b; ..."``."""
        if len(self.messages) == 1:
            raise SceneError(f"{self.source}: {self.messages[0]}")
        if self.messages:
            raise SceneError(
                f"{self.source}: {len(self.messages)} problems: " + "; ".join(self.messages)
            )


def field_error(source: str, field: str, problem: str) -> SceneError:
    """The one-line error of *field* of the scene named *source*."""
    return SceneError(f"{source}: {field}: {problem}")
