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
from ..path_kinds import file_type
from .blender import load_blend
from .generators import GeneratorOptions, generate
from .generators.view_rule import FrameProbe
from .meshes import MESH_SUFFIXES, load_mesh_scene
from .mitsuba_xml import load_mitsuba_xml
from .model import Scene
from .scene_reader import load_scene
from .semantic import SemanticRules, classify
from .validate import check_classes

__all__ = [
    "GeneratedSource",
    "FileSource",
    "scene_file_kind",
    "takes_asset_colours",
    "takes_material_map",
    "is_scene_file",
    "load_scene_file",
    "labelled",
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
    anything else. The one dispatcher of scene files (``render``, ``dataset --scenes``).
    A path that exists but is not a regular file (a FIFO, a device, a folder) is refused
    before it is opened: reading a FIFO would wait for a writer forever."""
    p = Path(path)
    if p.exists() and not p.is_file():
        raise SceneError(
            f"scene file {str(p)!r} is {file_type(p)}, not a regular file; expected a scene file"
        )
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

    An empty argument names nothing (``Path("")`` is the working folder, which exists).

    >>> is_scene_file("chair.OBJ"), is_scene_file("room.yaml"), is_scene_file("room-living")
    (True, True, False)
    >>> is_scene_file("")
    False
    """
    if not str(argument):
        return False
    p = Path(argument)
    return p.suffix.lower() in (".yaml", ".yml", ".xml", ".blend", *MESH_SUFFIXES) or p.exists()


def takes_asset_colours(path: str | Path) -> bool:
    """Whether ``--colours-from-asset`` applies to the scene file at *path*: a glTF/GLB, an OBJ
    (its MTL's ``Kd`` and ``map_Kd``) or a ``.blend`` file (their materials state a base
    colour); YAML, XML, PLY, STL and OFF files state none, so the option would do nothing there."""
    suffix = Path(path).suffix.lower()
    return suffix in (".glb", ".gltf", ".obj") or scene_file_kind(path) == "blend"


def takes_material_map(path: str | Path) -> bool:
    """Whether ``--material-map`` and ``--default-spectrum`` apply to the scene file at *path*:
    a mesh or ``.blend`` file, whose materials are names only; a YAML or Mitsuba XML scene
    states every material's spectrum itself, so the options would do nothing there."""
    return scene_file_kind(path) in ("mesh", "blend")


def load_scene_file(
    path: str | Path,
    *,
    width: int | None = None,
    height: int | None = None,
    materials: Mapping[str, str] | None = None,
    default_spectrum: str | None = None,
    data_dir: str | None = None,
    colours_from_asset: bool = True,
    approximate: bool = False,
    semantic: SemanticRules | None = None,
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
        Give mesh and ``.blend`` materials without a spectrum the colour or texture the file
        states (glTF base colour and texture, MTL ``Kd``/``map_Kd``, Principled Base Color;
        the default); False (``--no-colours-from-asset``): they are an error.
    approximate
        Approximate what a Mitsuba XML file or a ``.blend``'s World holds without exact ground
        truth instead of refusing it (``--approximate``); other kinds of file have nothing to
        approximate (the command line refuses the option where no scene file is either).
    semantic
        The user's semantic rules (``--semantic-map``), tried before the default map's
        (:func:`labelled`); None: the default map alone.
    """
    rules = semantic or SemanticRules()
    scene = _read_scene_file(
        path,
        width,
        height,
        materials,
        default_spectrum,
        data_dir,
        colours_from_asset,
        rules,
        approximate,
    )
    # a mesh file's reader labels its meshes itself: its materials keep only their spectra's names
    return scene if scene_file_kind(path) == "mesh" else labelled(scene, rules, str(path))


def labelled(scene: Scene, semantic: SemanticRules, source: str) -> Scene:
    """*scene* with each mesh's class taken from its object name, then its material names (in
    the order its faces use them), by *semantic*'s rules and then the default map's
    (:func:`~spectrinsic.scenes.semantic.classify`); SceneError naming *source* if meshes
    sharing an object id get different classes.

    A material named after its own spectrum (as every generated material is, and unnamed mesh
    materials) says nothing of the object and is passed over, so a saved generated scene read
    back gets its generator's classes (``sfu:sfu_lab_wall/1`` on a vase is no wall)."""
    chosen = semantic.compiled()
    meshes = []
    for mesh in scene.meshes:
        used = [scene.materials[i] for i in dict.fromkeys(int(i) for i in mesh.face_materials)]
        names = [mesh.name, *(m.name for m in used if m.name != m.spectrum)]
        meshes.append(dataclasses.replace(mesh, semantic=classify(names, chosen)))
    out = dataclasses.replace(scene, meshes=tuple(meshes))
    check_classes(out, source)
    return out


def _read_scene_file(
    path: str | Path,
    width: int | None,
    height: int | None,
    materials: Mapping[str, str] | None,
    default_spectrum: str | None,
    data_dir: str | None,
    colours_from_asset: bool,
    semantic: SemanticRules,
    approximate: bool,
) -> Scene:
    """The scene of *path* as its reader builds it (see :func:`load_scene_file`)."""
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
            semantic=semantic.compiled(),
        )
    if kind == "blend":
        return load_blend(
            path,
            materials=mapping or None,
            resolution=(width or FILE_SIZE, height or FILE_SIZE) if given else None,
            default_spectrum=default_spectrum,
            data_dir=data_dir,
            colours_from_asset=colours_from_asset,
            approximate=approximate,
        )
    if kind == "mitsuba":
        scene = load_mitsuba_xml(path, data_dir=data_dir, approximate=approximate)
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
        The colours and textures the file states, for materials without a spectrum.
    approximate
        Approximate what a Mitsuba XML file or a ``.blend``'s World holds without exact
        ground truth.
    semantic
        The user's semantic rules (``--semantic-map``), before the default map's.
    """

    path: str
    width: int | None
    height: int | None
    materials: tuple[tuple[str, str], ...] = ()
    default_spectrum: str | None = None
    colours_from_asset: bool = True
    approximate: bool = False
    semantic: SemanticRules = SemanticRules()

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
            approximate=self.approximate,
            semantic=self.semantic,
        )
