# Builds the Blender-exported atlas_gi benchmark scene and writes it as glTF
# binary: a Cornell box whose walls are closed 5 cm boxes, two boxes rotated
# 20 and 30 degrees about the vertical axis. The light and camera live in
# scenes/gi_blender_cornell.json (strahl's units, no exporter conversion).
#
#   blender -b --factory-startup --python tools/make_gi_blender_scene.py -- OUT.glb
#
# Coordinates below are strahl's (y up, metres); Blender is z up, and its
# glTF exporter maps Blender (x, y, z) to glTF (x, z, -y).
import math
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "gi_blender_cornell.glb"

for o in list(bpy.data.objects):
    bpy.data.objects.remove(o, do_unlink=True)


def material(name, rgb):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*rgb, 1.0)
    m.use_backface_culling = True  # exported as doubleSided: false (closed boxes)
    return m


def box(name, lo, hi, rgb, rot_y_deg=0.0):
    # A unit cube scaled to the box, centred on it, rotated about strahl's y.
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    o = bpy.context.active_object
    o.name = name
    c = [(a + b) / 2 for a, b in zip(lo, hi)]
    s = [b - a for a, b in zip(lo, hi)]
    o.location = (c[0], -c[2], c[1])
    o.scale = (s[0], s[2], s[1])
    o.rotation_euler = (0.0, 0.0, math.radians(rot_y_deg))
    o.data.materials.append(material(name, rgb))


t = 0.05
white, red, green = (0.75, 0.75, 0.75), (0.75, 0.1, 0.1), (0.1, 0.75, 0.1)
box("floor", (-1 - t, -t, -1 - t), (1 + t, 0, 1 + t), white)
box("ceiling", (-1 - t, 2, -1 - t), (1 + t, 2 + t, 1 + t), white)
box("back", (-1 - t, 0, -1 - t), (1 + t, 2, -1), white)
box("left", (-1 - t, 0, -1), (-1, 2, 1 + t), red)
box("right", (1, 0, -1), (1 + t, 2, 1 + t), green)
box("short", (0.1, 0, -0.1), (0.7, 0.6, 0.5), white, 20.0)
box("tall", (-0.7, 0, -0.7), (-0.1, 1.2, -0.1), white, 30.0)

bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_apply=True, export_lights=False,
                          export_cameras=False)
print("wrote", out)
