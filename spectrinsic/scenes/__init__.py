"""spectrinsic.scenes: scenes as plain data (geometry arrays + records naming spectra).

- :mod:`~spectrinsic.scenes.model`: the records (:class:`Scene`, :class:`Mesh`, ...);
- :mod:`~spectrinsic.scenes.scene_format`: the YAML scene format (``FORMAT.md``), read by
  :func:`load_scene` (:mod:`~spectrinsic.scenes.scene_reader`) and written by :func:`save_scene`
  (:mod:`~spectrinsic.scenes.scene_writer`);
- :mod:`~spectrinsic.scenes.validate`: :func:`validate_scene` (one-line errors);
- :mod:`~spectrinsic.scenes.textures`: :class:`Texture`, per-texel convex mixes of basis
  reflectances on a mesh, and their generated patterns (:func:`make_texture`);
- :mod:`~spectrinsic.scenes.parts` (painted parts, placement), :mod:`~spectrinsic.scenes.primitives`,
  :mod:`~spectrinsic.scenes.painting`, :mod:`~spectrinsic.scenes.furniture` and
  :mod:`~spectrinsic.scenes.objects`: procedural, painted geometry;
- :mod:`~spectrinsic.scenes.library`: the built-in scenes and illumination conditions (their
  geometry, views and light rigs: :mod:`~spectrinsic.scenes.layouts`);
- :mod:`~spectrinsic.scenes.sample_id`: :class:`SampleId`, a sample's scene, view and
  condition and its text form ``<scene>__v<view>__<condition>``;
- :mod:`~spectrinsic.scenes.blender`: :func:`load_blend` (optional extra ``blender``).
"""

from .blender import load_blend
from .library import CONDITIONS, build, default_samples, n_views, scene_names
from .model import Camera, Light, Material, Mesh, Scene, scene_hash, scene_to_dict
from .sample_id import SampleId
from .scene_reader import load_scene
from .scene_writer import save_scene
from .textures import Texture, make_texture
from .validate import validate_scene

__all__ = [
    "CONDITIONS",
    "Camera",
    "Light",
    "Material",
    "Mesh",
    "SampleId",
    "Scene",
    "Texture",
    "build",
    "default_samples",
    "load_blend",
    "load_scene",
    "make_texture",
    "n_views",
    "save_scene",
    "scene_hash",
    "scene_names",
    "scene_to_dict",
    "validate_scene",
]
