# Builds the cross-check scenes that are made the way users make them: in
# Blender, exported by its glTF exporter with the exporter's defaults
# (materials doubleSided: true, Blender's default with backface culling off;
# TEXCOORD_0 and normals; no cameras or lights: those live in the case's
# JSON, in strahl's units). Modifiers are applied in the scene, as a user
# applies them before export.
#
#   blender -b --factory-startup --python tools/crosscheck/make_user_scenes.py -- OUTDIR [NAME...]
#
# NAME: ds_cornell, meshes, dense, fog_room, cloud_room, spot_room (default: all). Coordinates below
# are strahl's (y up, metres); Blender is z up, and the exporter maps Blender
# (x, y, z) to glTF (x, z, -y).
import math
import os
import sys

import bpy

# Blender 3.4's glTF add-on uses np.bool, which numpy 1.24 (Debian 12) removed.
import numpy
if "bool" not in numpy.__dict__:
    numpy.bool = bool

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if not args:
    sys.stderr.write("usage: ... -- OUTDIR [NAME...]\n")
    sys.exit(2)
outdir, names = args[0], args[1:] or ["ds_cornell", "meshes", "dense", "fog_room", "cloud_room", "spot_room"]


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def material(name, rgb):
    # Principled BSDF base colour = the albedo; backface culling stays off
    # (the default), so the exporter writes doubleSided: true.
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*rgb, 1.0)
    return m


def place(o, centre, rot_y_deg=0.0, tilt_x_deg=0.0):
    o.location = (centre[0], -centre[2], centre[1])
    o.rotation_euler = (math.radians(tilt_x_deg), 0.0, math.radians(rot_y_deg))


def box(name, lo, hi, rgb, rot_y_deg=0.0):
    # A unit cube scaled to the box, centred on it, rotated about strahl's y.
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    o = bpy.context.active_object
    o.name = name
    place(o, [(a + b) / 2 for a, b in zip(lo, hi)], rot_y_deg)
    s = [b - a for a, b in zip(lo, hi)]
    o.scale = (s[0], s[2], s[1])
    o.data.materials.append(material(name, rgb))
    return o


def plane(name, centre, size_x, size_z, rgb, normal="y"):
    # An open double-sided wall: Blender's plane, rotated so that its normal
    # is strahl's +y (floor), +z (back wall) or +x (side wall).
    bpy.ops.mesh.primitive_plane_add(size=1.0)
    o = bpy.context.active_object
    o.name = name
    o.location = (centre[0], -centre[2], centre[1])
    o.scale = (size_x, size_z, 1.0)
    if normal == "z":
        o.rotation_euler = (math.radians(90), 0, 0)  # Blender +z -> -y = strahl +z
    elif normal == "x":
        o.rotation_euler = (math.radians(90), 0, math.radians(-90))  # -> strahl +x
    o.data.materials.append(material(name, rgb))
    return o


def smooth(o):
    bpy.context.view_layer.objects.active = o
    o.select_set(True)
    bpy.ops.object.shade_smooth()


def subdivide(o, levels):
    bpy.context.view_layer.objects.active = o
    m = o.modifiers.new("subsurf", "SUBSURF")
    m.levels = levels
    m.render_levels = levels
    bpy.ops.object.modifier_apply(modifier=m.name)


def export(name):
    path = os.path.join(outdir, name + ".glb")
    bpy.ops.export_scene.gltf(filepath=path)  # the exporter's defaults (GLB)
    tris = sum(len(p.vertices) - 2 for o in bpy.data.objects if o.type == "MESH"
               for p in o.data.polygons)
    print("make_user_scenes: %s (%d triangles, %d bytes)" % (path, tris, os.path.getsize(path)))


def ds_cornell():
    # The Cornell box of scenes/gi_blender_cornell.json (walls as closed 5 cm
    # boxes, two blocks rotated 20 and 30 degrees) with Blender's default
    # materials: double-sided.
    reset()
    t = 0.05
    white, red, green = (0.75, 0.75, 0.75), (0.75, 0.1, 0.1), (0.1, 0.75, 0.1)
    box("floor", (-1 - t, -t, -1 - t), (1 + t, 0, 1 + t), white)
    box("ceiling", (-1 - t, 2, -1 - t), (1 + t, 2 + t, 1 + t), white)
    box("back", (-1 - t, 0, -1 - t), (1 + t, 2, -1), white)
    box("left", (-1 - t, 0, -1), (-1, 2, 1 + t), red)
    box("right", (1, 0, -1), (1 + t, 2, 1 + t), green)
    box("short", (0.1, 0, -0.1), (0.7, 0.6, 0.5), white, 20.0)
    box("tall", (-0.7, 0, -0.7), (-0.1, 1.2, -0.1), white, 30.0)
    export("ds_cornell")


def meshes():
    # Meshes that are not boxes, on open double-sided walls: a smooth UV
    # sphere (Blender's default 32 x 16) and a smooth Suzanne, rotated and
    # tilted.
    reset()
    plane("floor", (0, 0, 0), 4, 4, (0.7, 0.7, 0.7))
    plane("back", (0, 1.25, -2), 4, 2.5, (0.6, 0.6, 0.7), "z")
    plane("left", (-2, 1.25, 0), 4, 2.5, (0.7, 0.2, 0.15), "x")
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5)
    s = bpy.context.active_object
    s.name = "sphere"
    place(s, (-0.7, 0.5, -0.6))
    s.data.materials.append(material("sphere", (0.75, 0.75, 0.75)))
    smooth(s)
    bpy.ops.mesh.primitive_monkey_add(size=1.0)
    m = bpy.context.active_object
    m.name = "suzanne"
    place(m, (0.6, 0.55, 0.1), rot_y_deg=-35.0, tilt_x_deg=20.0)
    m.data.materials.append(material("suzanne", (0.8, 0.55, 0.2)))
    smooth(m)
    export("meshes")


def dense():
    # A scene of more than 100k triangles: 26 smooth Suzannes subdivided
    # once (3936 triangles each), linked duplicates (one mesh, as Alt+D
    # makes: the exporter writes it once and 26 nodes use it) on a floor.
    reset()
    plane("floor", (0, 0, 0), 8, 8, (0.7, 0.7, 0.7))
    bpy.ops.mesh.primitive_monkey_add(size=0.8)
    first = bpy.context.active_object
    first.data.materials.append(material("suzanne", (0.75, 0.6, 0.45)))
    subdivide(first, 1)
    smooth(first)
    k = 0
    for j in range(5):
        for i in range(6):
            if k >= 26:
                break
            o = first if k == 0 else first.copy()  # shares first.data
            if k:
                bpy.context.scene.collection.objects.link(o)
            o.name = "suzanne%02d" % k
            place(o, (-2.5 + i + 0.3 * (j % 2), 0.45, -2.2 + j), rot_y_deg=37.0 * k,
                  tilt_x_deg=-15.0 + 7.0 * (k % 5))
            k += 1
    export("dense")


def fog_room():
    # A room of closed wall boxes with a window (a cross of mullions) in the
    # left wall and two blocks, for god rays: the light stands outside.
    reset()
    wall, t = (0.6, 0.6, 0.6), 0.2
    box("floor", (-3.2, -t, -3.2), (3.2, 0, 3.2), (0.6, 0.55, 0.5))
    box("ceiling", (-3.2, 3, -3.2), (3.2, 3 + t, 3.2), (0.7, 0.7, 0.7))
    box("back", (-3.2, 0, -3.2), (3.2, 3, -3), wall)
    box("front", (-3.2, 0, 3), (3.2, 3, 3.2), wall)
    box("right", (3, 0, -3), (3.2, 3, 3), wall)
    box("left_low", (-3.2, 0, -3), (-3, 1, 3), wall)
    box("left_high", (-3.2, 2.2, -3), (-3, 3, 3), wall)
    box("left_a", (-3.2, 1, -3), (-3, 2.2, -0.9), wall)
    box("left_b", (-3.2, 1, 0.9), (-3, 2.2, 3), wall)
    box("mullion_v", (-3.15, 1, -0.04), (-3.05, 2.2, 0.04), (0.4, 0.3, 0.2))
    box("mullion_h", (-3.15, 1.56, -0.9), (-3.05, 1.64, 0.9), (0.4, 0.3, 0.2))
    box("table", (-0.9, 0, -1.6), (0.3, 0.75, -0.8), (0.5, 0.35, 0.25), 15.0)
    box("cabinet", (0.9, 0, 0.6), (1.5, 1.8, 1.1), (0.3, 0.4, 0.5), -25.0)
    export("fog_room")


def cloud_room():
    # A floor, a back wall and a pedestal under a cloud (the case's OpenVDB
    # grid, cloud.vdb) lit by a spot from above: the cloud's shadow on the
    # floor, its self-shadowing and the lit cone in its density.
    reset()
    box("floor", (-2.5, -0.1, -2.5), (2.5, 0, 2.5), (0.6, 0.55, 0.5))
    box("back", (-2.5, 0, -1.6), (2.5, 3, -1.5), (0.6, 0.6, 0.6))
    box("pedestal", (0.5, 0, -0.6), (0.9, 0.5, -0.2), (0.3, 0.4, 0.5), 20.0)
    export("cloud_room")


def spot_room():
    # A room of closed wall boxes lit by a spot under its ceiling (the light
    # is in the case's JSON), for god rays in the spot's cone: a slatted
    # grille of three bars below the spot cuts the cone into shafts, which
    # fall on a smooth Suzanne and a block on the floor.
    reset()
    wall, t = (0.6, 0.6, 0.6), 0.2
    box("floor", (-3.2, -t, -3.2), (3.2, 0, 3.2), (0.6, 0.55, 0.5))
    box("ceiling", (-3.2, 3, -3.2), (3.2, 3 + t, 3.2), (0.7, 0.7, 0.7))
    box("back", (-3.2, 0, -3.2), (3.2, 3, -3), wall)
    box("left", (-3.2, 0, -3), (-3, 3, 3.2), wall)
    box("right", (3, 0, -3), (3.2, 3, 3.2), wall)
    for k, x in enumerate((-0.75, -0.35, 0.05)):
        box("bar%d" % k, (x, 2.2, -1.6), (x + 0.14, 2.28, -0.2), (0.4, 0.3, 0.2), 10.0)
    box("block", (0.3, 0, -1.9), (1.0, 0.7, -1.2), (0.3, 0.4, 0.5), -20.0)
    bpy.ops.mesh.primitive_monkey_add(size=0.9)
    m = bpy.context.active_object
    m.name = "suzanne"
    place(m, (-0.6, 0.45, -0.7), rot_y_deg=25.0, tilt_x_deg=-10.0)
    m.data.materials.append(material("suzanne", (0.8, 0.55, 0.2)))
    smooth(m)
    export("spot_room")


os.makedirs(outdir, exist_ok=True)
for n in names:
    {"ds_cornell": ds_cornell, "meshes": meshes, "dense": dense, "fog_room": fog_room,
     "cloud_room": cloud_room, "spot_room": spot_room}[n]()
