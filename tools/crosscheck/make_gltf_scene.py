# Builds the small glTF test scene of the cross-check suite in Blender and
# exports it as .glb (Y up, KHR_lights_punctual, base colours, no textures):
#   blender -b --factory-startup --python tools/crosscheck/make_gltf_scene.py -- OUT.glb
# Blender is z-up; the exporter converts to glTF's y-up.
import math
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)


def mat(name, rgb, double_sided=True):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*rgb, 1.0)
    m.use_backface_culling = not double_sided  # the exporter writes doubleSided = not culling
    return m


def put(obj, m):
    obj.data.materials.append(m)
    return obj


bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0, 0, 0))
put(bpy.context.object, mat("floor", (0.6, 0.6, 0.55), double_sided=False))
bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-0.8, -0.4, 0.5))
put(bpy.context.object, mat("cube", (0.7, 0.25, 0.2)))
bpy.ops.mesh.primitive_cube_add(size=0.8, location=(0.9, -0.9, 0.4), rotation=(0, 0, math.radians(30)))
put(bpy.context.object, mat("cube2", (0.25, 0.5, 0.7), double_sided=False))
bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.5, location=(0.3, 0.7, 0.5))
bpy.ops.object.shade_smooth()
put(bpy.context.object, mat("sphere", (0.7, 0.7, 0.7)))
# a back wall (glTF z = -3), a single-sided plane facing the camera
bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0, 3, 3), rotation=(math.radians(90), 0, 0))
put(bpy.context.object, mat("wall", (0.5, 0.6, 0.5), double_sided=False))
light = bpy.data.lights.new("lamp", "POINT")
light.energy = 4 * math.pi * 3.0  # 3 W/sr
light.shadow_soft_size = 0.0
lo = bpy.data.objects.new("lamp", light)
lo.location = (1.2, 1.0, 2.6)
bpy.context.scene.collection.objects.link(lo)
bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_yup=True, export_lights=True,
                          export_cameras=False, export_apply=True, export_texcoords=False,
                          convert_lighting_mode="SPEC")
