"""Build a .blend with an image-textured plane for tests/scenes/test_blender_textures.py (run in a
subprocess: bpy state is global).

Usage: python make_textured_blend.py -- OUT.blend IMAGE.png PACK(0|1)

A 2 × 2 plane in z = 0 (UVs (x + 1) / 2, (y + 1) / 2) whose material "Checker" has an Image
Texture node (the PNG, sRGB, Closest, REPEAT; packed into the file when PACK is 1) linked into
its Principled Base Color; a camera above it and a sun.
"""

import sys

import bpy

out, image_path, pack = sys.argv[-3], sys.argv[-2], sys.argv[-1] == "1"
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

me = bpy.data.meshes.new("plane")
me.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
uv = me.uv_layers.new(name="UVMap")
for loop in me.loops:
    x, y, _ = me.vertices[loop.vertex_index].co
    uv.data[loop.index].uv = ((x + 1) / 2, (y + 1) / 2)
me.update()
plane = bpy.data.objects.new("Plane", me)
mat = bpy.data.materials.new("Checker")
mat.use_nodes = True
nodes = mat.node_tree.nodes
principled = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
tex = nodes.new("ShaderNodeTexImage")
tex.image = bpy.data.images.load(image_path)
tex.image.colorspace_settings.name = "sRGB"
tex.interpolation, tex.extension = "Closest", "REPEAT"
mat.node_tree.links.new(tex.outputs["Color"], principled.inputs["Base Color"])
if pack:
    tex.image.pack()
plane.data.materials.append(mat)
scene.collection.objects.link(plane)

cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
cam.location = (0, 0, 4)
scene.collection.objects.link(cam)
scene.camera = cam
scene.render.resolution_x = scene.render.resolution_y = 16
sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
scene.collection.objects.link(sun)
bpy.ops.wm.save_as_mainfile(filepath=out, relative_remap=True)
