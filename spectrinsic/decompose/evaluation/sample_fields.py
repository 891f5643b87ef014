"""What the evaluation reads off a loaded sample: its id, condition, kind, mask and input image.

Samples are the dicts :func:`spectrinsic.gt_export.load_sample` returns; the evaluation
(:mod:`spectrinsic.decompose.evaluation.evaluate`) and the parameter search script read them through these
functions only.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...scenes.lighting import LightingCondition, describe_lighting
from ...scenes.sample_id import SampleId
from .scores import CONDITION_GROUPS, INPUT_LAYERS

__all__ = [
    "BACKGROUND_OBJECTS",
    "evaluation_mask",
    "input_image",
    "material_ids",
    "sample_condition",
    "sample_id_of",
    "sample_kind",
    "sample_lighting",
]

_KINDS = {"object": "single objects", "complex": "complex scenes"}


def sample_id_of(sample: Mapping[str, Any]) -> str:
    """The sample's id: ``meta["sample_id"]``, else its ``sample_id`` key."""
    meta = sample.get("meta", {})
    sid = meta.get("sample_id") or sample.get("sample_id")
    if not sid:
        raise DatasetError("sample has no meta['sample_id']")
    return str(sid)


def sample_lighting(sample: Mapping[str, Any]) -> LightingCondition:
    """The sample's lighting measured from ``meta["lights"]``
    (:func:`spectrinsic.scenes.lighting.describe_lighting`)."""
    try:
        return describe_lighting(sample.get("meta", {}).get("lights") or [])
    except ValueError as exc:
        raise DatasetError(f"sample {sample_id_of(sample)!r}: {exc}") from None


def sample_condition(sample: Mapping[str, Any]) -> str:
    """Lighting condition: the library's (``meta["condition"]``, else the sample id's, when it
    is one of :data:`CONDITION_GROUPS` and the scene was not generated), else the group
    measured from the sample's lights (``WL``, ``1L``, ``2L``: :func:`sample_lighting`), so
    generated sets, scene files and relit samples are grouped by what they hold."""
    meta = sample.get("meta", {})
    cond = meta.get("condition")
    if not cond:
        try:
            cond = SampleId.parse(sample_id_of(sample)).condition
        except DatasetError:  # a user's own id
            cond = None
    if cond in CONDITION_GROUPS and "generator" not in meta.get("scene_metadata", {}):
        return str(cond)
    return sample_lighting(sample).group


def sample_kind(sample: Mapping[str, Any]) -> str:
    """``"object"`` or ``"complex"``: ``meta["scene_kind"]``, else the ``obj-`` id prefix."""
    meta = sample.get("meta", {})
    kind = meta.get("scene_kind") or meta.get("scene_metadata", {}).get("kind")
    if not kind:
        kind = "object" if sample_id_of(sample).startswith("obj") else "complex"
    if kind not in _KINDS:
        raise DatasetError(f"sample {sample_id_of(sample)!r}: unknown scene kind {kind!r}")
    return str(kind)


#: Object names excluded from the evaluation mask of single-object scenes: like the MIT
#: benchmark (Grosse et al. 2009), an object is scored on its own mask, not on the ground.
BACKGROUND_OBJECTS = frozenset({"ground"})


def evaluation_mask(sample: Mapping[str, Any]) -> np.ndarray:
    """Pixels scored: the ``mask``, minus background objects in single-object scenes."""
    image = np.asarray(sample["image"])
    mask = np.asarray(sample.get("mask", np.ones(image.shape[:2], bool)), dtype=bool)
    if sample_kind(sample) != "object":
        return mask
    objects = sample.get("meta", {}).get("objects") or {}
    ids = sample.get("ids")
    object_ids = ids.get("object") if isinstance(ids, Mapping) else None
    background = [int(k) for k, name in objects.items() if name in BACKGROUND_OBJECTS]
    if object_ids is None or not background:
        return mask
    return mask & ~np.isin(np.asarray(object_ids), background)


def material_ids(sample: Mapping[str, Any]) -> np.ndarray | None:
    """The per-pixel material ids (``ids["material"]``), or ``None`` when the sample has none."""
    ids = sample.get("ids")
    if isinstance(ids, Mapping):
        ids = ids.get("material", ids.get("material_id"))
    return None if ids is None else np.asarray(ids)


def input_image(sample: Mapping[str, Any], camera: str | None = None) -> tuple[str, np.ndarray]:
    """The image a method decomposes: the first of :data:`INPUT_LAYERS` the sample has.

    For a camera, ``image_camera_denoised/<camera>`` else ``image_camera/<camera>``.
    Returns ``(layer key, float64 array)``.
    """
    keys = [
        f"{k.replace('image', 'image_camera', 1)}/{camera}" if camera else k for k in INPUT_LAYERS
    ]
    for key in keys:
        if key in sample:
            return key, np.asarray(sample[key], dtype=np.float64)
    raise DatasetError(f"sample {sample_id_of(sample)!r} has none of the layers {keys}")
