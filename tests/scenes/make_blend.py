"""Build a small .blend for tests/scenes/test_blender.py (run in a subprocess: bpy state is global).

Usage: python make_blend.py -- OUT.blend MARKER_PATH WITH_CAMERA(0|1) UNKNOWN_MATERIAL(0|1)

The scene: a unit cube placed by T(1, 2, 0.5) Rz(90 deg) S(2, 1, 1) whose first 4 quads use
material "munsell:5R 4/14" (named after its spectrum) and last 2 use "Paint" (mapped by the
caller, Principled Base Color (0.2, 0.3, 0.6)); a ground quad with material "Floor" (custom property spectrum = "flat:0.5"); point,
spot, area and sun lights; a 35 mm lens on a 36 mm sensor, 64 x 48 px; and a registered text
block that writes MARKER_PATH if Blender ever runs the file's Python.
"""

import math
import sys

import bpy

out, marker = sys.argv[-4], sys.argv[-3]
with_camera, unknown_material = sys.argv[-2] == "1", sys.argv[-1] == "1"
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def material(name, spectrum=None):
    m = bpy.data.materials.new(name)
    if spectrum:
        m["spectrum"] = spectrum
    return m


# a unit cube (8 vertices, 6 quads) placed by a transform: world = T(1,2,0.5) Rz(90) S(2,1,1)
verts = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
me = bpy.data.meshes.new("cube")
me.from_pydata(verts, [], quads)
me.update()
cube = bpy.data.objects.new("Cube", me)
cube.data.materials.append(material("munsell:5R 4/14"))
paint = material("Paint")
# a Principled Base Color, read only with colours_from_asset=True (the node exists by default)
next(n for n in paint.node_tree.nodes if n.type == "BSDF_PRINCIPLED").inputs[
    "Base Color"
].default_value = (0.2, 0.3, 0.6, 1.0)
cube.data.materials.append(paint)
for i, poly in enumerate(me.polygons):
    poly.material_index = 0 if i < 4 else 1
cube.location = (1.0, 2.0, 0.5)
cube.rotation_euler = (0.0, 0.0, math.pi / 2)
cube.scale = (2.0, 1.0, 1.0)
scene.collection.objects.link(cube)

ground_me = bpy.data.meshes.new("ground")
ground_me.from_pydata(
    [(-5, -5, -0.1), (5, -5, -0.1), (5, 5, -0.1), (-5, 5, -0.1)], [], [(0, 1, 2, 3)]
)
ground = bpy.data.objects.new("Ground", ground_me)
ground.data.materials.append(
    material("Floor", "munsell:5R 4/15" if unknown_material else "flat:0.5")
)
scene.collection.objects.link(ground)


def light(name, kind, energy, location, rotation=(0, 0, 0), **attrs):
    data = bpy.data.lights.new(name, kind)
    data.energy = energy
    for k, v in attrs.items():
        setattr(data, k, v)
    obj = bpy.data.objects.new(name, data)
    obj.location, obj.rotation_euler = location, rotation
    scene.collection.objects.link(obj)
    return obj


light("Lamp", "POINT", 100.0, (0, 0, 4))["spectrum"] = "planck:2800K"
light("Spot", "SPOT", 200.0, (3, 0, 3), (0, math.radians(45), 0), spot_size=math.radians(60))
light("Panel", "AREA", 50.0, (0, 3, 3), shape="RECTANGLE", size=0.5, size_y=0.25)
light("Sun", "SUN", 3.0, (0, 0, 10), (math.radians(30), 0, 0))

if with_camera:
    cam_data = bpy.data.cameras.new("Cam")
    cam_data.lens, cam_data.sensor_width, cam_data.sensor_fit = 35.0, 36.0, "HORIZONTAL"
    cam = bpy.data.objects.new("Cam", cam_data)
    cam.location = (1.0, -6.0, 0.5)
    cam.rotation_euler = (math.pi / 2, 0.0, 0.0)  # looks along +y with +z up
    scene.collection.objects.link(cam)
    scene.camera = cam
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = (
    64,
    48,
    100,
)

# a registered text block: Blender runs it on load when auto-execution is allowed
text = bpy.data.texts.new("autorun.py")
text.write(f"open({marker!r}, 'w').write('ran')\n")
text.use_module = True
bpy.ops.wm.save_as_mainfile(filepath=out)
