"""spectrinsic.scenes: scenes as plain data (geometry arrays + records naming spectra).

- :mod:`~spectrinsic.scenes.model`: the records (:class:`Scene`, :class:`Mesh`, ...);
- :mod:`~spectrinsic.scenes.io`: the YAML scene format (``FORMAT.md``), :func:`load_scene`,
  :func:`save_scene`;
- :mod:`~spectrinsic.scenes.validate`: :func:`validate_scene` (one-line errors);
- :mod:`~spectrinsic.scenes.geometry` and :mod:`~spectrinsic.scenes.objects`: procedural,
  painted geometry;
- :mod:`~spectrinsic.scenes.library`: the built-in scenes and illumination conditions;
- :mod:`~spectrinsic.scenes.sample_id`: :class:`SampleId`, a sample's scene, view and
  condition and its text form ``<scene>__v<view>__<condition>``;
- :mod:`~spectrinsic.scenes.blender`: :func:`load_blend` (optional extra ``blender``).
"""

from spectrinsic.scenes.blender import load_blend
from spectrinsic.scenes.io import load_scene, save_scene
from spectrinsic.scenes.library import (
    CONDITIONS,
    build,
    default_samples,
    n_views,
    scene_names,
)
from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene, scene_hash, scene_to_dict
from spectrinsic.scenes.sample_id import SampleId
from spectrinsic.scenes.validate import validate_scene

__all__ = [
    "CONDITIONS",
    "Camera",
    "Light",
    "Material",
    "Mesh",
    "SampleId",
    "Scene",
    "build",
    "default_samples",
    "load_blend",
    "load_scene",
    "n_views",
    "save_scene",
    "scene_hash",
    "scene_names",
    "scene_to_dict",
    "validate_scene",
]
