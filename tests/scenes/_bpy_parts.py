"""Pieces of the small .blend files the tests build with bpy (``tests/scenes/make_*.py``, run
by :func:`tests.scenes._builders.build_blend` in a subprocess: bpy state is global). Lengths in
Blender units, Z up; names as the readers see them.

Imported by the scripts, run by path under ``python -P``, after they put this folder on
``sys.path``; bpy is imported here, so nothing in the test run imports this module.
"""

import bpy

#: A unit cube's corners and its 6 quads (outward), centred at the origin.
CUBE_VERTICES = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
CUBE_QUADS = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]


def empty_scene():
    """Blender's factory settings with an empty scene; the scene."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context.scene


def linked(scene, name, data):
    """A new object *name* of *data* in *scene*'s collection."""
    obj = bpy.data.objects.new(name, data)
    scene.collection.objects.link(obj)
    return obj


def uv_plane(scene, material):
    """A 2 × 2 plane "Plane" in z = 0, its UV map "UVMap" ((x + 1) / 2, (y + 1) / 2), of a new
    node material *material*; returns the material."""
    me = bpy.data.meshes.new("plane")
    me.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    uv = me.uv_layers.new(name="UVMap")
    for loop in me.loops:
        x, y, _ = me.vertices[loop.vertex_index].co
        uv.data[loop.index].uv = ((x + 1) / 2, (y + 1) / 2)
    me.update()
    mat = bpy.data.materials.new(material)
    mat.use_nodes = True
    me.materials.append(mat)
    linked(scene, "Plane", me)
    return mat


def unit_cube(scene, material):
    """The unit cube "Cube" at the origin (:data:`CUBE_QUADS`) of *material*; the object."""
    me = bpy.data.meshes.new("cube")
    me.from_pydata(CUBE_VERTICES, [], CUBE_QUADS)
    me.update()
    me.materials.append(material)
    return linked(scene, "Cube", me)


def camera(scene, location, pixels, name="Cam"):
    """The scene's camera *name* at *location* (looking down −Z until turned), rendering
    *pixels* ``(width, height)`` at 100 %; the object."""
    cam = linked(scene, name, bpy.data.cameras.new(name))
    cam.location = location
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y = pixels
    scene.render.resolution_percentage = 100
    return cam


def sun(scene):
    """A sun lamp "Sun" (Blender's default strength and direction, straight down)."""
    return linked(scene, "Sun", bpy.data.lights.new("Sun", "SUN"))
