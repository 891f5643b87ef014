"""Build a .blend with an image-textured plane for tests/scenes/test_blender_textures.py (run in a
subprocess: bpy state is global).

Usage: python make_textured_blend.py -- OUT.blend IMAGE.png PACK(0|1)

A 2 × 2 plane in z = 0 (UVs (x + 1) / 2, (y + 1) / 2) whose material "Checker" has an Image
Texture node (the PNG, sRGB, Closest, REPEAT; packed into the file when PACK is 1) linked into
its Principled Base Color; a camera above it and a sun.
"""

import sys
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run by path under -P: _bpy_parts
from _bpy_parts import camera, empty_scene, sun, uv_plane  # noqa: E402

out, image_path, pack = sys.argv[-3], sys.argv[-2], sys.argv[-1] == "1"
scene = empty_scene()
mat = uv_plane(scene, "Checker")
nodes = mat.node_tree.nodes
principled = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
tex = nodes.new("ShaderNodeTexImage")
tex.image = bpy.data.images.load(image_path)
tex.image.colorspace_settings.name = "sRGB"
tex.interpolation, tex.extension = "Closest", "REPEAT"
mat.node_tree.links.new(tex.outputs["Color"], principled.inputs["Base Color"])
if pack:
    tex.image.pack()
camera(scene, (0, 0, 4), (16, 16))
sun(scene)
bpy.ops.wm.save_as_mainfile(filepath=out, relative_remap=True)
