"""``spectrinsic render``'s SCENE argument: a scene file or a library scene name, as a
:class:`~spectrinsic.scenes.model.Scene`."""

from __future__ import annotations

from collections.abc import Mapping

from ..pipeline.presets import get_preset
from ..render.base.variants import import_mitsuba
from ..scenes import library
from ..scenes.model import Scene
from ..scenes.sources import is_scene_file, load_scene_file

__all__ = ["load_scene_argument"]


def load_scene_argument(
    scene: str,
    *,
    condition: str,
    view: int,
    seed: int,
    width: int | None,
    height: int | None,
    materials: Mapping[str, str] | None = None,
    default_spectrum: str | None = None,
    data_dir: str | None = None,
    colours_from_asset: bool = True,
    approximate: bool = False,
) -> Scene:
    """The Scene named by the ``SCENE`` argument: a scene file (YAML, ``.blend`` or mesh,
    :func:`spectrinsic.scenes.sources.load_scene_file`, the dispatch ``dataset --scenes`` uses),
    else a library scene at the default preset's size unless *width*/*height* say otherwise."""
    if is_scene_file(scene):
        import_mitsuba()  # set up before a Mitsuba XML read imports it (the libLLVM Dr.Jit loads)
        return load_scene_file(
            scene,
            width=width,
            height=height,
            materials=materials,
            default_spectrum=default_spectrum,
            data_dir=data_dir,
            colours_from_asset=colours_from_asset,
            approximate=approximate,
        )
    default = get_preset("default")
    return library.build(
        scene,
        view=view,
        condition=condition,
        seed=seed,
        width=default.width if width is None else width,
        height=default.height if height is None else height,
    )
