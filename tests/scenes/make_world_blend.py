"""Build the .blend files of tests/scenes/test_blender_world.py, one per World (run in a
subprocess: bpy state is global).

Usage: python make_world_blend.py -- FOLDER

FOLDER holds ``maps/patch.exr`` and ``maps/smooth.exr`` (written by the test) and, beside
FOLDER, ``outside.exr``. Every file holds the same scene: a unit cube at the origin of material
``flat:0.8`` (named after its spectrum), a camera at (3, 2.5, 2.2) looking at the origin,
24 x 24 pixels, no lamps. Their Worlds (see :data:`WORLDS`):

- ``colour``: a Background of Color (0.8, 0.4, 0.2) and Strength 2.5;
- ``zero``: a Sky Texture feeding the Color, at Strength 0; ``black``: black at Strength 3;
- ``hdri``: an Environment Texture of ``//maps/patch.exr``, its Vector unlinked, Strength 1;
- ``turned``: ``//maps/smooth.exr`` through Texture Coordinate Generated -> Mapping (POINT,
  rotation Z 90 deg), Strength 2;
- ``tilted``: that Mapping also turned 10 deg about X; ``sky``: a Sky Texture feeds the Color
  (the Background's own colour (0.1, 0.2, 0.3), Strength 2);
- ``mix``: a Mix Shader of two Backgrounds is the Surface; ``packed``: ``hdri`` with the image
  packed; ``escape``: an image ``//../outside.exr`` (working spaces: make_colour_blends.py).
"""

import math
import sys
from pathlib import Path

import bpy
from mathutils import Vector

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run by path under -P: _bpy_parts
from _bpy_parts import camera, empty_scene, unit_cube  # noqa: E402

folder = Path(sys.argv[-1])
scene = empty_scene()
unit_cube(scene, bpy.data.materials.new("flat:0.8"))
cam = camera(scene, (3.0, 2.5, 2.2), (24, 24))
cam.rotation_euler = (Vector((0, 0, 0)) - cam.location).to_track_quat("-Z", "Y").to_euler()
bpy.ops.wm.save_as_mainfile(filepath=str(folder / "base.blend"))  # "//" is FOLDER from here on


def world(name):
    """A new World of *name* with nodes, its Background node and output, made the scene's."""
    w = bpy.data.worlds.new(name)
    w.use_nodes = True
    scene.world = w
    nodes = w.node_tree.nodes
    return w, nodes["Background"], nodes["World Output"]


def background(name, colour, strength):
    w, bg, _ = world(name)
    bg.inputs["Color"].default_value = (*colour, 1.0)
    bg.inputs["Strength"].default_value = strength
    return w


def environment(name, image, strength=1.0):
    w, bg, _ = world(name)
    tex = w.node_tree.nodes.new("ShaderNodeTexEnvironment")
    tex.image = bpy.data.images.load(str(image))
    tex.image.filepath = "//" + image.relative_to(folder).as_posix()  # Blender's relative path
    tex.image.colorspace_settings.name = "Linear Rec.709"
    w.node_tree.links.new(tex.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = strength
    return w, tex


def mapped(name, rotation):
    w, tex = environment(name, folder / "maps" / "smooth.exr", 2.0)
    nodes, links = w.node_tree.nodes, w.node_tree.links
    coords, mapping = nodes.new("ShaderNodeTexCoord"), nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    mapping.inputs["Rotation"].default_value = rotation
    links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], tex.inputs["Vector"])


def sky(name="Sky", strength=2.0):
    w = background(name, (0.1, 0.2, 0.3), strength)
    tex = w.node_tree.nodes.new("ShaderNodeTexSky")
    w.node_tree.links.new(tex.outputs["Color"], w.node_tree.nodes["Background"].inputs["Color"])


def mix():
    w = background("Mixed", (1.0, 1.0, 1.0), 1.0)
    nodes, links = w.node_tree.nodes, w.node_tree.links
    other, shader = nodes.new("ShaderNodeBackground"), nodes.new("ShaderNodeMixShader")
    links.new(nodes["Background"].outputs[0], shader.inputs[1])
    links.new(other.outputs[0], shader.inputs[2])
    links.new(shader.outputs[0], nodes["World Output"].inputs["Surface"])


def packed():
    _, tex = environment("Packed", folder / "maps" / "patch.exr")
    tex.image.pack()


def escape():
    _, tex = environment("Escape", folder / "maps" / "patch.exr")
    tex.image.filepath = "//../outside.exr"


WORLDS = {
    "colour": lambda: background("World", (0.8, 0.4, 0.2), 2.5),
    "zero": lambda: sky("Zero", 0.0),
    "black": lambda: background("Black", (0.0, 0.0, 0.0), 3.0),
    "hdri": lambda: environment("HDRI", folder / "maps" / "patch.exr"),
    "turned": lambda: mapped("Turned", (0.0, 0.0, math.pi / 2)),
    "tilted": lambda: mapped("Tilted", (math.radians(10), 0.0, math.pi / 2)),
    "sky": sky,
    "mix": mix,
    "packed": packed,
    "escape": escape,
}

for stem, build in WORLDS.items():
    build()
    bpy.ops.wm.save_as_mainfile(filepath=str(folder / f"{stem}.blend"), relative_remap=True)
