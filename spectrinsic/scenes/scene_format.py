"""The YAML scene format: a human-editable file <-> :class:`~spectrinsic.scenes.model.Scene`.

Read by :mod:`spectrinsic.scenes.scene_reader` (:func:`load_scene`), written by
:mod:`spectrinsic.scenes.scene_writer` (:func:`save_scene`); this module holds the vocabulary
both share.

Format (version 1; the full reference with an example is ``spectrinsic/scenes/FORMAT.md``)::

    format: 1                        # optional format version
    name: red-cup                    # scene name
    materials:                       # material name -> reflectance spectrum name
      red: "munsell:5R 4/14"
      ground: "flat:0.5"
    meshes:
      - name: cup                    # unique mesh name
        object_id: 1                 # optional; default: position in the list
        file: meshes/cup.ply         # an OBJ/PLY/STL/OFF file in this file's folder (or below) ...
        transform:                   # optional, for files: scale, rotate (x, y, z degrees), translate
          scale: 0.5
          rotate_deg: [0, 0, 30]
          translate: [0, 0, 0.1]
        material: red                # one material for every face ...
      - name: ground
        vertices: [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]   # ... or inline geometry
        faces: [[0, 1, 2], [0, 2, 3]]
        face_materials: [[ground, 2]]  # ... or [material, count] runs over the faces in order
    lights:
      - kind: point                  # point | spot | area | directional
        spectrum: "cie:D65"          # illuminant spectrum name
        power: 4.0                   # > 0
        position: [1, -1, 2]
    camera:
      origin: [0.6, -0.8, 0.5]
      target: [0, 0, 0.1]
      up: [0, 0, 1]                  # optional
      fov_deg: 40                    # optional, horizontal
      width: 128
      height: 128
    metadata: {}                     # optional, free-form

Paths are relative to the YAML file's folder and stay inside it (the reader rejects absolute
paths and paths leading out of it). Meshes with many faces are written as double-precision
binary PLY files in ``<stem>_meshes/``, so ``load_scene(save_scene(s, p)) == s``.
"""

from __future__ import annotations

__all__ = ["FORMAT_VERSION", "MESH_SUFFIXES"]

FORMAT_VERSION = 1
#: Mesh file types read through trimesh.
MESH_SUFFIXES = (".obj", ".ply", ".stl", ".off")
