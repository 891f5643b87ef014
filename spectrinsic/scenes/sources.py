"""Where a dataset sample's scene comes from: a generator draw or a scene file.

A source is a small picklable record that a worker turns into a
:class:`~spectrinsic.scenes.model.Scene` with :meth:`build`; the planner never ships a scene.
Scene files are YAML (``FORMAT.md``), ``.blend`` (optional extra ``blender``; scripts never
run) or meshes (:data:`~spectrinsic.scenes.meshes.MESH_SUFFIXES`, with a material map).
"""

from __future__ import annotations

import dataclasses
import gzip
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from ..errors import SceneError
from .blender import load_blend
from .generators import GeneratorOptions, generate
from .generators.view_rule import FrameProbe
from .meshes import MESH_SUFFIXES, load_mesh_scene
from .mitsuba_xml import load_mitsuba_xml
from .model import Scene
from .scene_reader import load_scene

__all__ = [
    "GeneratedSource",
    "FileSource",
    "scene_file_kind",
    "is_scene_file",
    "load_scene_file",
    "FILE_SIZE",
]

#: First bytes of every uncompressed ``.blend`` file.
BLEND_MAGIC = b"BLENDER"
#: First bytes of a gzip stream and of a zstd frame (Blender compresses ``.blend`` files so).
GZIP_MAGIC = b"\x1f\x8b"
ZSTD_MAGIC = b"\x28\xb5\x2f\xfd"
#: Image side in pixels of a file without a camera size of its own (a mesh), or of the side a
#: caller left out when it gave the other.
FILE_SIZE = 128


@dataclass(frozen=True)
class GeneratedSource:
    """Scene *index* of *generator* under the dataset's root seed, seen from camera *view*."""

    generator: str
    root_seed: int
    index: int
    view: int
    options: GeneratorOptions

    def build(self, data_dir: str | None = None, probe: FrameProbe | None = None) -> Scene:
        """Generate the scene (deterministic: same record and *probe*, same scene); *probe*
        judges the rendered light of the views (:func:`~.generators.generate`)."""
        options = dataclasses.replace(self.options, data_dir=data_dir)
        return generate(
            self.generator,
            root_seed=self.root_seed,
            index=self.index,
            view=self.view,
            options=options,
            probe=probe,
        )


def _compressed_blend(head: bytes, path: Path) -> bool:
    """True for a gzip- or zstd-compressed file whose content starts with Blender's magic."""
    if head.startswith(GZIP_MAGIC):
        try:
            with gzip.open(path, "rb") as fh:
                return fh.read(len(BLEND_MAGIC)) == BLEND_MAGIC
        except (OSError, EOFError):
            return False
    if head.startswith(ZSTD_MAGIC):
        try:
            import zstandard
        except ImportError:  # Blender writes zstd .blend files; without a reader, trust the magic
            return True
        try:
            with path.open("rb") as raw, zstandard.ZstdDecompressor().stream_reader(raw) as fh:
                return fh.read(len(BLEND_MAGIC)) == BLEND_MAGIC
        except (OSError, zstandard.ZstdError):
            return False
    return False


def scene_file_kind(path: str | Path) -> str:
    """``"yaml"``, ``"mitsuba"`` (``.xml``), ``"blend"`` or ``"mesh"`` for a scene file, by suffix; a ``.blend`` also by
    its magic bytes, plain or compressed (gzip, zstd), under any name. One-line error for
    anything else. The one dispatcher of scene files (``render``, ``dataset --scenes``)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix in (".yaml", ".yml"):
        return "yaml"
    if suffix in MESH_SUFFIXES:
        return "mesh"
    if suffix == ".blend":
        return "blend"
    if suffix == ".xml":
        return "mitsuba"
    try:
        with p.open("rb") as fh:
            head = fh.read(len(BLEND_MAGIC))
        if head == BLEND_MAGIC or _compressed_blend(head, p):
            return "blend"
    except OSError:
        pass
    raise SceneError(
        f"scene file {str(p)!r}: expected .yaml/.yml, .xml (Mitsuba 3), .blend (plain, gzip or zstd) "
        f"or a mesh ({', '.join(MESH_SUFFIXES)})"
    )


def is_scene_file(argument: str | Path) -> bool:
    """Whether a scene argument names a file (a scene-file suffix, or an existing path) rather
    than a library scene.

    >>> is_scene_file("chair.OBJ"), is_scene_file("room.yaml"), is_scene_file("room-living")
    (True, True, False)
    """
    p = Path(argument)
    return p.suffix.lower() in (".yaml", ".yml", ".xml", ".blend", *MESH_SUFFIXES) or p.exists()


def load_scene_file(
    path: str | Path,
    *,
    width: int | None = None,
    height: int | None = None,
    materials: Mapping[str, str] | None = None,
    default_spectrum: str | None = None,
    data_dir: str | None = None,
    colours_from_asset: bool = False,
) -> Scene:
    """Read any scene file (:func:`scene_file_kind`) into a validated scene: the one dispatch
    over YAML, ``.blend`` and mesh files, for ``dataset --scenes`` and ``render``.

    Parameters
    ----------
    width, height
        Image size in pixels; ``None`` keeps the file's camera size (a YAML or ``.blend`` file;
        a mesh, which has none, and a side left out beside a given one take :data:`FILE_SIZE`).
    materials
        Material name -> spectrum, for meshes and ``.blend`` files.
    default_spectrum
        Reflectance of mesh or ``.blend`` materials not in *materials*.
    colours_from_asset
        Give glTF and ``.blend`` materials without a spectrum the file's base colour as an
        ``rgb:`` reflectance (``--colours-from-asset``); False: they are an error.
    """
    kind = scene_file_kind(path)
    mapping = dict(materials or {})
    given = width is not None or height is not None
    if kind == "mesh":
        return load_mesh_scene(
            path,
            materials=mapping,
            width=width or FILE_SIZE,
            height=height or FILE_SIZE,
            default_spectrum=default_spectrum,
            data_dir=data_dir,
            colours_from_asset=colours_from_asset,
        )
    if kind == "blend":
        return load_blend(
            path,
            materials=mapping or None,
            resolution=(width or FILE_SIZE, height or FILE_SIZE) if given else None,
            default_spectrum=default_spectrum,
            data_dir=data_dir,
            colours_from_asset=colours_from_asset,
        )
    if kind == "mitsuba":
        scene = load_mitsuba_xml(path, data_dir=data_dir)
    else:
        scene = load_scene(path, data_dir=data_dir)
    camera = dataclasses.replace(
        scene.camera,
        width=scene.camera.width if width is None else width,
        height=scene.camera.height if height is None else height,
    )
    return dataclasses.replace(scene, camera=camera)


@dataclass(frozen=True)
class FileSource:
    """A scene file rendered at ``width x height`` (the file's camera, resized; ``None``: the
    file's own size, :data:`FILE_SIZE` for a mesh).

    Attributes
    ----------
    materials
        Material name -> spectrum pairs, for meshes and ``.blend`` files.
    default_spectrum
        Reflectance of mesh or ``.blend`` materials not in *materials*.
    colours_from_asset
        Base colours of glTF and ``.blend`` materials without a spectrum as ``rgb:`` spectra.
    """

    path: str
    width: int | None
    height: int | None
    materials: tuple[tuple[str, str], ...] = ()
    default_spectrum: str | None = None
    colours_from_asset: bool = False

    def build(self, data_dir: str | None = None) -> Scene:
        """Read and validate the file; one-line :class:`SceneError` naming it on bad input."""
        return load_scene_file(
            self.path,
            width=self.width,
            height=self.height,
            materials=dict(self.materials),
            default_spectrum=self.default_spectrum,
            data_dir=data_dir,
            colours_from_asset=self.colours_from_asset,
        )
