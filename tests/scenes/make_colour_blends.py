"""Build the .blend files of tests/scenes/test_blender_colours.py in one subprocess (bpy state
is global): each file the colours of one material, or a World, in a working colour space.

Usage: python make_colour_blends.py -- FOLDER

FOLDER holds ``texel.png`` (written by the test). Every file is built from Blender's factory
settings: a 2 x 2 plane in z = 0 (UVs (x + 1) / 2, (y + 1) / 2) of one material, a camera
above it, 16 x 16 pixels, and a sun (none in ``dropped``). See :data:`FILES`; "converted"
means Blender's own ``wm.set_working_color_space(convert_colors=True)`` moved the file's
colours, set in Linear Rec.709, to another working space:

- ``paint``: a Principled Base Color (0.2, 0.4, 0.6) on material ``Paint`` (no spectrum name);
  ``paint_2020``, ``paint_aces``: that file converted to Linear Rec.2020, ACEScg;
- ``saturated``: Base Color (0.05, 0.9, 0.05) set in a Linear Rec.2020 file (outside Rec. 709);
- ``named_wide``: material ``flat:0.8`` (named after its spectrum) in ACEScg: no colour read;
- ``glass_aces``: material ``flat:0.5`` of Transmission 1 and Base Color (0.9, 0.8, 0.7),
  converted to ACEScg;
- ``world_2020``: ``named_wide``'s plane under a World of Color (0.8, 0.4, 0.2) and Strength
  2.5, converted to Linear Rec.2020;
- image textures (``//texel.png``, Closest, REPEAT) feeding material ``Paint``'s Base Color:
  ``texture_2020`` (sRGB, in a Linear Rec.2020 file), ``alpha`` (the node's Alpha output feeds
  it), ``muted`` (the link is muted), ``xyz`` (image colour space Linear CIE-XYZ D65),
  ``noncolor`` (Non-Color: the texels read as they are), ``noncolor_2020`` (Non-Color in a
  Linear Rec.2020 file);
- ``dropped``: material ``flat:0.8``, no sun, a World whose Surface is a Mix Shader of two
  Backgrounds (left out by ``--approximate``).
"""

import sys
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run by path under -P: _bpy_parts
from _bpy_parts import camera, empty_scene, sun, uv_plane  # noqa: E402

folder = Path(sys.argv[-1])


def plane(material):
    """A fresh file of the plane of *material*, a camera and a sun; returns the material."""
    scene = empty_scene()
    mat = uv_plane(scene, material)
    camera(scene, (0, 0, 4), (16, 16))
    sun(scene)
    return mat


def principled(mat):
    return next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")


def paint(rgb=(0.2, 0.4, 0.6)):
    principled(plane("Paint")).inputs["Base Color"].default_value = (*rgb, 1.0)


def world():
    plane("flat:0.8")
    w = bpy.data.worlds.new("World")
    bpy.context.scene.world = w
    w.node_tree.nodes["Background"].inputs["Color"].default_value = (0.8, 0.4, 0.2, 1.0)
    w.node_tree.nodes["Background"].inputs["Strength"].default_value = 2.5


def glass():
    node = principled(plane("flat:0.5"))
    node.inputs["Transmission Weight"].default_value = 1.0
    node.inputs["Base Color"].default_value = (0.9, 0.8, 0.7, 1.0)


def texture(space="sRGB", output="Color", muted=False):
    mat = plane("Paint")
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = bpy.data.images.load(str(folder / "texel.png"))
    tex.image.colorspace_settings.name = space
    tex.interpolation, tex.extension = "Closest", "REPEAT"
    link = mat.node_tree.links.new(tex.outputs[output], principled(mat).inputs["Base Color"])
    link.is_muted = muted


def dropped():
    plane("flat:0.8")
    bpy.data.objects.remove(bpy.data.objects["Sun"])
    w = bpy.data.worlds.new("Mixed")
    bpy.context.scene.world = w
    nodes, links = w.node_tree.nodes, w.node_tree.links
    other, shader = nodes.new("ShaderNodeBackground"), nodes.new("ShaderNodeMixShader")
    links.new(nodes["Background"].outputs[0], shader.inputs[1])
    links.new(other.outputs[0], shader.inputs[2])
    links.new(shader.outputs[0], nodes["World Output"].inputs["Surface"])


#: stem: (build, working space, whether Blender converts the colours to it)
FILES = {
    "paint": (paint, None, False),
    "paint_2020": (paint, "Linear Rec.2020", True),
    "paint_aces": (paint, "ACEScg", True),
    "saturated": (lambda: paint((0.05, 0.9, 0.05)), "Linear Rec.2020", False),
    "named_wide": (lambda: plane("flat:0.8"), "ACEScg", False),
    "glass_aces": (glass, "ACEScg", True),
    "world_2020": (world, "Linear Rec.2020", True),
    "texture_2020": (texture, "Linear Rec.2020", False),
    "alpha": (lambda: texture(output="Alpha"), None, False),
    "muted": (lambda: texture(muted=True), None, False),
    "xyz": (lambda: texture("Linear CIE-XYZ D65"), None, False),
    "noncolor": (lambda: texture("Non-Color"), None, False),
    "noncolor_2020": (lambda: texture("Non-Color"), "Linear Rec.2020", False),
    "dropped": (dropped, None, False),
}

for stem, (build, space, convert) in FILES.items():
    build()
    if space is not None:
        bpy.ops.wm.set_working_color_space(working_space=space, convert_colors=convert)
    path = folder / f"{stem}.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), relative_remap=True)
