"""The geometry family: ``mask``, ``depth``, ``normals`` and the integer ids (material, object
and semantic class), and the material coverage the other families weight by.
"""

from __future__ import annotations

import logging

import numpy as np

from ...errors import DatasetError
from ...scenes.model import Scene
from ...scenes.semantic import class_id
from .records import Layer, SampleInputs, aov, make_layer

# Responses with the light's white at Y = 1; under D65 with sRGB sensors, the canonical p^{s,c}.

__all__ = ["coverage_of", "geometry_layers", "semantic_ids", "SEMANTIC_UNITS"]

log = logging.getLogger(__name__)


_GEOMETRY = (
    ("depth", ("Z",), "scene units, distance from the camera to the first hit (0: background)"),
    ("normals", ("X", "Y", "Z"), "world-space unit surface normals (0: background)"),
    (
        "material_id",
        ("id",),
        "index into meta['materials'], int32 (an EXR UINT channel holding "
        "the int32 bits); -1 background",
    ),
    (
        "object_id",
        ("id",),
        "object id of the scene meshes, int32 (an EXR UINT channel holding "
        "the int32 bits); -1 background",
    ),
)


_ID_LAYERS = ("material_id", "object_id")
SEMANTIC_UNITS = (
    "semantic class id of the object seen (the object_id layer's), an index into "
    "meta['semantic_classes'], int32 (an EXR UINT channel holding the int32 bits); -1 background"
)


def _ids(name: str, value: np.ndarray) -> np.ndarray:
    """An id AOV as int32: whole numbers in [-1, 2**31 - 1] (-1 background), else an error."""
    value = np.asarray(value)
    ints = value if value.dtype.kind in "iu" else np.rint(value)
    if value.size and ((ints != value).any() or ints.min() < -1 or ints.max() >= 2**31):
        raise DatasetError(f"render AOV {name!r}: expected whole ids from -1 to 2**31 - 1")
    return ints.astype(np.int32)


def semantic_ids(scene: Scene, object_id: np.ndarray) -> np.ndarray:
    """``(H, W)`` int32 class ids (:mod:`~spectrinsic.scenes.semantic`) of an object-id map:
    each pixel's object's class, -1 background. The scene check gives an object id one class, so
    every pixel of one object has one class and the layers agree by construction."""
    ids = np.asarray(object_id, np.int64)
    out = np.full(ids.shape, -1, np.int32)
    for mesh in scene.meshes:
        out[ids == mesh.object_id] = class_id(mesh.semantic)
    if ((ids >= 0) & (out < 0)).any():
        raise DatasetError("render AOV 'object_id' holds an id that no scene mesh has")
    return out


def coverage_of(s: SampleInputs, shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """``(H, W, M)`` material coverage and the ``(H, W)`` mask of the render."""
    mask = aov(s.result, "mask")
    mask = np.ones(shape, bool) if mask is None else mask.astype(bool)
    coverage = aov(s.result, "coverage")
    if coverage is None:
        material_id = aov(s.result, "material_id")
        if material_id is None:
            raise DatasetError("render result has neither a 'coverage' nor a 'material_id' AOV")
        log.warning("no coverage AOV: reflectance is not anti-aliased at edges")
        coverage = (material_id[..., None] == np.arange(len(s.scene.materials))).astype(float)
    return np.asarray(coverage, float), mask


def geometry_layers(s: SampleInputs, mask: np.ndarray) -> list[Layer]:
    out = [
        make_layer(
            "mask",
            mask,
            ("Y",),
            "1 where a surface covers the pixel centre, else 0",
            "geometry",
            nonnegative=True,
        )
    ]
    for name, channels, units in _GEOMETRY:
        value = aov(s.result, name)
        if value is None:
            continue
        if name in _ID_LAYERS:
            out.append(Layer(name, _ids(name, value), channels, units, "geometry"))
            if name == "object_id":
                semantic = semantic_ids(s.scene, out[-1].data)
                out.append(Layer("semantic", semantic, ("id",), SEMANTIC_UNITS, "geometry"))
        else:
            out.append(
                make_layer(name, value, channels, units, "geometry", nonnegative=name == "depth")
            )
    return out
