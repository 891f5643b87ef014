"""The sample id: which scene, camera view and lighting condition a dataset sample shows.

One record and one text form, ``<scene>__v<view>__<condition>`` (e.g.
``obj-vase__v0__two-colour-a``, ``objects-on-ground-00001__v0__white``), used as the sample's
folder name, its ``meta.json["sample_id"]`` and its seed key. The dataset build writes it,
evaluation and the tuning protocol read it back with :meth:`SampleId.parse`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import DatasetError

__all__ = ["SampleId", "SEPARATOR"]

#: Separator of the three fields in the text form.
SEPARATOR = "__"
#: The text form; the scene may itself hold ``__`` (a scene file's stem), view and condition not.
_PATTERN = re.compile(r"(?P<scene>.+)__v(?P<view>\d+)__(?P<condition>(?:(?!__).)+)")


@dataclass(frozen=True)
class SampleId:
    """One sample of a dataset: a scene, a view and an illumination condition.

    Attributes
    ----------
    scene
        The scene's name (a library scene, a generated scene or a scene file's stem).
    view
        Index of the camera view, >= 0.
    condition
        The lighting condition (``white``, ``two-colour-a``, ..., ``file`` for scene files).

    >>> str(SampleId("obj-vase", 0, "two-colour-a"))
    'obj-vase__v0__two-colour-a'
    >>> SampleId.parse("room-living__v2__white")
    SampleId(scene='room-living', view=2, condition='white')
    """

    scene: str
    view: int
    condition: str

    def __str__(self) -> str:
        return f"{self.scene}{SEPARATOR}v{self.view}{SEPARATOR}{self.condition}"

    @classmethod
    def parse(cls, text: str) -> SampleId:
        """The id whose text form is *text* (``<scene>__v<view>__<condition>``).

        Raises
        ------
        DatasetError
            If *text* is not of that form; the message names it and shows the form.
        """
        match = _PATTERN.fullmatch(str(text))
        if match is None:
            raise DatasetError(
                f"sample id {text!r} is not of the form '<scene>__v<view>__<condition>' "
                "(e.g. 'obj-vase__v0__two-colour-a')"
            )
        return cls(match["scene"], int(match["view"]), match["condition"])
