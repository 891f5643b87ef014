"""Mitsuba XML ``envmap`` emitters as environment maps (:mod:`~spectrinsic.scenes.envmaps`)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..errors import SceneError
from .budget import SceneBudget
from .envmaps import check_map_file, envmap_lights
from .mitsuba_files import confined_file, file_sha256
from .mitsuba_tree import XmlNode
from .model import Light

__all__ = ["ENVMAP_PARAMS", "envmap_emitter"]

#: The parameters of an ``envmap`` read.
ENVMAP_PARAMS = {"filename", "scale", "to_world"}


def envmap_emitter(node: XmlNode, where: str, base: Path, index: int) -> list[Light]:
    """The three channel lights of an ``envmap`` (:mod:`~spectrinsic.scenes.envmaps`): its
    file confined to the scene's folder and checked (OpenEXR or Radiance HDR, size, texels),
    ``scale`` and the rotation ``to_world``; the file's *index*-th map (from 1) is named by its
    id, else ``envmap``, ``envmap_2`` ...."""
    extra = set(node.props) - ENVMAP_PARAMS
    if extra:
        raise SceneError(
            f"{where}: unsupported parameter {sorted(extra)[0]!r} in {node.label()}; "
            f"expected {', '.join(sorted(ENVMAP_PARAMS))}"
        )
    rel = node.props.get("filename")
    if not isinstance(rel, str):
        raise SceneError(f"{where}: {node.label()} has no filename")
    path = confined_file(rel, base, where)
    check_map_file(path, where, SceneBudget(where))
    scale = node.number("scale", 1.0)
    if not (math.isfinite(scale) and scale > 0):
        raise SceneError(f"{where}: scale {scale!r}; expected a finite number > 0")
    m = np.asarray(node.props.get("to_world", np.eye(4)), float)
    rot = m[:3, :3]
    if not (np.allclose(rot @ rot.T, np.eye(3), atol=1e-6) and np.linalg.det(rot) > 0):
        raise SceneError(f"{where}: to_world of {node.label()} is not a rotation")
    name = node.id if node.id and not node.id.startswith("_unnamed") else "envmap"
    name += "" if index == 1 else f"_{index}"  # the file's maps stay told apart
    return list(envmap_lights(name, str(path), file_sha256(path), scale, rot.ravel().tolist()))
