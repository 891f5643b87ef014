"""Build a .blend with Principled BSDF materials for tests/scenes/test_blender_gloss.py
(run in a subprocess: bpy state is global).

Usage: python make_blend_gloss.py -- OUT.blend [R,G,B | textured | glass-bsdf:R,G,B |
glass-bsdf:textured]

Three quads side by side: "Copper" (Metallic 1, Roughness 0.3, custom property metal = "Cu"),
"munsell:5R 4/14" (Metallic 0, Roughness 0.2, IOR 1.45), "flat:0.5" (Roughness 0.8) and
"Glass" (Transmission 1, Roughness 0, IOR 1.52; its Base Color white, or R,G,B, or fed by an
Image Texture node with ``textured``; with ``glass-bsdf:`` a Glass BSDF node of that Color,
IOR 1.52, instead of the Principled); a camera above and a sun.
"""

import sys
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run by path under -P: _bpy_parts
from _bpy_parts import camera, empty_scene, linked, sun  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1 :]
out, tint = args[0], (args[1] if len(args) > 1 else "1,1,1")
scene = empty_scene()


def principled(name, metallic, roughness, ior=1.5):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    node = next(n for n in m.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    node.inputs["Metallic"].default_value = metallic
    node.inputs["Roughness"].default_value = roughness
    node.inputs["IOR"].default_value = ior
    return m


copper = principled("Copper", 1.0, 0.3)
copper["metal"] = "Cu"
glass = principled("Glass", 0.0, 0.0, 1.52)
node = next(n for n in glass.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
key = "Transmission Weight" if "Transmission Weight" in node.inputs else "Transmission"
node.inputs[key].default_value = 1.0
glass_bsdf = tint.startswith("glass-bsdf:")
if glass_bsdf:  # the Principled replaced by a Glass BSDF feeding the output
    tint = tint.split(":", 1)[1]
    glass.node_tree.nodes.remove(node)
    node = glass.node_tree.nodes.new("ShaderNodeBsdfGlass")
    node.inputs["IOR"].default_value, node.inputs["Roughness"].default_value = 1.52, 0.0
    output = next(n for n in glass.node_tree.nodes if n.type == "OUTPUT_MATERIAL")
    glass.node_tree.links.new(node.outputs["BSDF"], output.inputs["Surface"])
colour_input = node.inputs["Color" if glass_bsdf else "Base Color"]
if tint == "textured":
    image = glass.node_tree.nodes.new("ShaderNodeTexImage")
    png = str(Path(out).with_name("tint.png"))  # beside the .blend, where the reader looks
    made = bpy.data.images.new("tint", 4, 4)
    made.filepath_raw, made.file_format = png, "PNG"
    made.save()
    image.image = bpy.data.images.load(png)
    glass.node_tree.links.new(image.outputs["Color"], colour_input)
else:  # white: Blender's 0.8 would tint it
    colour_input.default_value = (*map(float, tint.split(",")), 1.0)
mats = [
    copper,
    principled("munsell:5R 4/14", 0.0, 0.2, 1.45),
    principled("flat:0.5", 0.0, 0.8),
    glass,
]
for i, mat in enumerate(mats):
    me = bpy.data.meshes.new(f"quad{i}")
    x = 2.0 * i - 2.0
    me.from_pydata(
        [(x - 1, -1, 0), (x + 1, -1, 0), (x + 1, 1, 0), (x - 1, 1, 0)], [], [(0, 1, 2, 3)]
    )
    if tint == "textured":  # the image's coordinates
        me.uv_layers.new(name="UVMap")
    me.update()
    me.materials.append(mat)
    linked(scene, f"Quad{i}", me)

camera(scene, (0.0, 0.0, 8.0), (32, 16), name="Camera")
sun(scene).data.energy = 2.0
bpy.ops.wm.save_as_mainfile(filepath=out)
