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
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run by path under -P: _bpy_parts
from _bpy_parts import camera, empty_scene, unit_cube  # noqa: E402

out, marker = sys.argv[-4], sys.argv[-3]
with_camera, unknown_material = sys.argv[-2] == "1", sys.argv[-1] == "1"
scene = empty_scene()


def material(name, spectrum=None):
    m = bpy.data.materials.new(name)
    if spectrum:
        m["spectrum"] = spectrum
    return m


# a unit cube (8 vertices, 6 quads) placed by a transform: world = T(1,2,0.5) Rz(90) S(2,1,1)
cube = unit_cube(scene, material("munsell:5R 4/14"))
paint = material("Paint")
# a Principled Base Color, read only with colours_from_asset=True (the node exists by default)
next(n for n in paint.node_tree.nodes if n.type == "BSDF_PRINCIPLED").inputs[
    "Base Color"
].default_value = (0.2, 0.3, 0.6, 1.0)
cube.data.materials.append(paint)
for i, poly in enumerate(cube.data.polygons):
    poly.material_index = 0 if i < 4 else 1
cube.location = (1.0, 2.0, 0.5)
cube.rotation_euler = (0.0, 0.0, math.pi / 2)
cube.scale = (2.0, 1.0, 1.0)

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
    cam = camera(scene, (1.0, -6.0, 0.5), (64, 48))
    cam.data.lens, cam.data.sensor_width, cam.data.sensor_fit = 35.0, 36.0, "HORIZONTAL"
    cam.rotation_euler = (math.pi / 2, 0.0, 0.0)  # looks along +y with +z up
else:
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    scene.render.resolution_percentage = 100

# a registered text block: Blender runs it on load when auto-execution is allowed
text = bpy.data.texts.new("autorun.py")
text.write(f"open({marker!r}, 'w').write('ran')\n")
text.use_module = True
bpy.ops.wm.save_as_mainfile(filepath=out)
