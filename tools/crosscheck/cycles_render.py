# Renders a strahl scene (JSON v1) with Blender Cycles in strahl's units, so
# strahl's images can be checked against an independent renderer.
#
#   blender -b --factory-startup --python tools/crosscheck/cycles_render.py -- \
#       SCENE.json OUT [--spp N] [--seeds A,B] [--size WxH] [--bounces K] [--threads T] [--float]
#       [--filter point|box]
#
# With two seeds it writes OUT.exr (the mean of the two renders), OUT_se.exr
# (per pixel |a - b| / 2, an unbiased one-sample estimate of the standard
# error of that mean: E[(a-b)^2/4] = var(a)/2 = var(mean)) and OUT.json (the
# settings, the render times and summary noise statistics). Both EXRs are
# HALF, ZIP-compressed, channels R, G, B. With one seed it writes OUT.exr
# only. --float writes 32-bit EXRs (calibration renders).
#
# The mapping of strahl's model onto Cycles (README.md in this folder says
# how each was checked):
#  - coordinates: strahl is y-up, Blender z-up; every position is rotated by
#    +90 degrees about x ((x, y, z) -> (x, -z, y)), the same rotation Blender's
#    glTF importer applies, so imported glTF files land in the same frame;
#  - point light of I W/sr: Cycles point light of power 4 pi I W, radius 0;
#  - directional light of irradiance E W/m^2: Cycles sun of strength E,
#    angle 0, shining along the direction (refused with a medium);
#  - spot light: a point light of 4 pi I W whose emission strength is glTF's
#    falloff computed by nodes (Cycles' own spot adds a cos factor and a
#    smoothstep, README.md);
#  - surfaces: Diffuse BSDF (Lambert) with the albedo, plus Emission of
#    strength 1 (Cycles: outgoing radiance = colour x strength), on the front
#    side only: a Mix Shader on Geometry.Backfacing selects a black Diffuse
#    BSDF on the back side (it absorbs and casts shadows) unless double_sided;
#  - medium: world volume = Volume Scatter (colour x density = sigma_s,
#    anisotropy g) + Volume Absorption ((1 - colour) x density = sigma_a),
#    homogeneous, equiangular sampling; volume bounces 0 (single scattering);
#  - medium.density.height: both volume densities times e^(-k (y - y0)) by
#    nodes on Geometry.Position, a heterogeneous world volume ray-marched in
#    steps of --volume-step metres (default 0.02);
#  - medium.density.vdb: no world volume; a Blender volume object reads the
#    grid (the scene's transform as its object matrix), with a Principled
#    Volume: density = sigma_t (grey: sigma_s + sigma_a must be equal per
#    channel), colour = sigma_s / sigma_t, absorption colour black, so
#    Cycles' sigma_s = colour x density and sigma_a = (1 - colour) x
#    density; anisotropy g; the object shifted by half a voxel (Cycles
#    samples voxel i at index i + 0.5, OpenVDB and strahl at i); the grid
#    trilinear, in full precision, not clipped, marched at a quarter voxel
#    (volume_step_rate 0.25), transparent bounces allowed (the volume's
#    bounding mesh is a transparent surface to Cycles);
#  - bounces: K diffuse bounces (max bounces K) where K is atlas_gi's or
#    ssgi's `bounces` parameter (default 1) when the scene uses one of them,
#    else 0. Emission lights other surfaces only through strahl's bounce
#    (L0 = emission + direct); Cycles counts an emitter hit as direct light,
#    so emission is gated to paths with at most K diffuse reflections
#    before it (camera rays always see it), and emitters are found by BSDF
#    sampling only so that the gate sees the true depth;
#  - camera: pinhole, fov_y the full vertical field of view (sensor fit
#    vertical), clip start 1e-5 m (camera rays start at the clip start),
#    pixel filter: `--filter point` (default) a Gaussian of width 0.01 px,
#    i.e. one ray through each pixel's centre like strahl's point filter
#    (measured on a plane with a box and its shadow: relMSE 1.2e-3 with the
#    1 px box, 3.6e-8 with this filter); `--filter box` Cycles' standard
#    1 px box (the mean radiance over the pixel, what users render with);
#  - no clamping, no denoising, no adaptive sampling, no glossy filter,
#    light sampling threshold 0, black world, Standard view, exposure 0.
import array
import json
import math
import os
import sys
import time

import bpy

BLACK = (0.0, 0.0, 0.0)


def fail(msg):
    sys.stderr.write("cycles_render: %s\n" % msg)
    sys.exit(2)


def parse_args(argv):
    a = argv[argv.index("--") + 1:] if "--" in argv else []
    opt = {"spp": 256, "seeds": [1, 2], "size": None, "bounces": None, "threads": 2, "float": False,
           "volume_step": 0.02, "filter": "point"}
    pos = []
    i = 0
    while i < len(a):
        k = a[i]
        if k == "--float":
            opt["float"] = True
        elif k == "--filter":
            if i + 1 >= len(a) or a[i + 1] not in ("point", "box"):
                fail("--filter: expected point or box")
            opt["filter"] = a[i + 1]
            i += 1
        elif k in ("--spp", "--seeds", "--size", "--bounces", "--threads", "--volume-step"):
            if i + 1 >= len(a):
                fail("%s: missing value" % k)
            v = a[i + 1]
            i += 1
            try:
                if k == "--seeds":
                    opt["seeds"] = [int(s) for s in v.split(",")]
                    if len(opt["seeds"]) not in (1, 2):
                        raise ValueError
                elif k == "--volume-step":
                    opt["volume_step"] = float(v)
                    if not opt["volume_step"] > 0:
                        raise ValueError
                elif k == "--size":
                    w, h = v.lower().split("x")
                    opt["size"] = (int(w), int(h))
                else:
                    opt[k[2:]] = int(v)
            except ValueError:
                fail("%s %s: bad value" % (k, v))
        elif k.startswith("-"):
            fail("%s: unknown option" % k)
        else:
            pos.append(k)
        i += 1
    if len(pos) != 2:
        fail("usage: ... -- SCENE.json OUT [--spp N] [--seeds A,B] [--size WxH] [--bounces K] [--threads T] "
             "[--float] [--volume-step M] [--filter point|box]")
    return pos[0], pos[1], opt


def to_blender(p):
    return (p[0], -p[2], p[1])


def vec3(d, key, default=None):
    v = d.get(key, default)
    if v is None or len(v) != 3:
        fail("%s: expected 3 numbers" % key)
    return [float(x) for x in v]


# --- geometry, the same vertices and winding as framework/st_mesh.c ---------

def quad_faces(c, u, v, verts, faces):
    b = len(verts)
    for p in (c, [c[k] + u[k] for k in range(3)], [c[k] + u[k] + v[k] for k in range(3)],
              [c[k] + v[k] for k in range(3)]):
        verts.append(to_blender(p))
    faces.append((b, b + 1, b + 2, b + 3))


def box_faces(mn, mx, inward, verts, faces):
    dx, dy, dz = mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2]
    f = [
        (mn, (0, 0, dz), (0, dy, 0)),
        ((mx[0], mn[1], mn[2]), (0, dy, 0), (0, 0, dz)),
        (mn, (dx, 0, 0), (0, 0, dz)),
        ((mn[0], mx[1], mn[2]), (0, 0, dz), (dx, 0, 0)),
        (mn, (0, dy, 0), (dx, 0, 0)),
        ((mn[0], mn[1], mx[2]), (dx, 0, 0), (0, dy, 0)),
    ]
    for c, u, v in f:
        quad_faces(c, v if inward else u, u if inward else v, verts, faces)


def sphere_mesh(center, radius, rings, segments):
    verts, normals, faces = [], [], []
    R, S = rings, segments
    for i in range(R + 1):
        th = math.pi * i / R
        st = 0.0 if i in (0, R) else math.sin(th)
        ct = 1.0 if i == 0 else -1.0 if i == R else math.cos(th)
        for j in range(S + 1):
            ph = 2.0 * math.pi * (j % S) / S
            n = (st * math.cos(ph), ct, -st * math.sin(ph))
            normals.append(to_blender(n))
            verts.append(to_blender([center[k] + radius * n[k] for k in range(3)]))
    for i in range(R):
        for j in range(S):
            a = i * (S + 1) + j
            b = a + S + 1
            c, d = b + 1, a + 1
            if i != R - 1:
                faces.append((a, b, c))
            if i != 0:
                faces.append((a, c, d))
    return verts, normals, faces


def material(name, albedo, emission, double_sided, bounces):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    diff = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diff.inputs["Color"].default_value = (*albedo, 1.0)
    diff.inputs["Roughness"].default_value = 0.0
    front = diff.outputs["BSDF"]
    if max(emission) > 0:
        em = nt.nodes.new("ShaderNodeEmission")
        em.inputs["Color"].default_value = (*emission, 1.0)
        # Strength 1 on camera rays and on paths with at most `bounces`
        # diffuse reflections before the emitter (strahl: emission lights
        # other surfaces only through the bounce). The emitter is found by
        # BSDF sampling only (not sampled as a light), so the depth at the
        # hit is the number of reflections; with light sampling, MIS would mix
        # the two estimators' differently gated values.
        m.cycles.sample_as_light = False
        lp = nt.nodes.new("ShaderNodeLightPath")
        lt = nt.nodes.new("ShaderNodeMath")
        lt.operation = "LESS_THAN"
        nt.links.new(lp.outputs["Diffuse Depth"], lt.inputs[0])
        lt.inputs[1].default_value = bounces + 0.5
        mx = nt.nodes.new("ShaderNodeMath")
        mx.operation = "MAXIMUM"
        nt.links.new(lt.outputs[0], mx.inputs[0])
        nt.links.new(lp.outputs["Is Camera Ray"], mx.inputs[1])
        nt.links.new(mx.outputs[0], em.inputs["Strength"])
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(front, add.inputs[0])
        nt.links.new(em.outputs["Emission"], add.inputs[1])
        front = add.outputs["Shader"]
    if double_sided:
        nt.links.new(front, out.inputs["Surface"])
        return m
    back = nt.nodes.new("ShaderNodeBsdfDiffuse")
    back.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(geo.outputs["Backfacing"], mix.inputs["Fac"])
    nt.links.new(front, mix.inputs[1])
    nt.links.new(back.outputs["BSDF"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    return m


def no_terminator_offset(ob):
    # Cycles 3.x moves shadow-ray origins of smooth low-poly meshes (default
    # geometry offset 0.1); strahl shades the interpolated normal as it is.
    ob.cycles.shadow_terminator_geometry_offset = 0.0
    ob.cycles.shadow_terminator_offset = 0.0


def add_mesh(name, verts, faces, mat, normals=None):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.update()
    if normals is not None:
        me.polygons.foreach_set("use_smooth", [True] * len(me.polygons))
        me.use_auto_smooth = True
        me.normals_split_custom_set_from_vertices(normals)
    me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    no_terminator_offset(ob)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def import_gltf(path, entry, bounces, index):
    # Blender 3.4's importer uses np.bool, which numpy 1.24 (Debian 12) removed.
    import numpy
    if "bool" not in numpy.__dict__:
        numpy.bool = bool
    before = set(bpy.data.objects)
    bpy.ops.import_scene.gltf(filepath=path, convert_lighting_mode="SPEC")
    new = [o for o in bpy.data.objects if o not in before]
    for o in new:
        if o.type == "CAMERA":
            bpy.data.objects.remove(o)  # the JSON camera is used
        elif o.type == "LIGHT":
            if o.data.type != "POINT":
                fail("geometry[%d].gltf: only point lights are supported" % index)
            o.data.shadow_soft_size = 0.0
        elif o.type == "MESH":
            no_terminator_offset(o)
            for slot in o.material_slots:
                src = slot.material
                if src is not None and src.get("strahl_made"):
                    continue  # a mesh shared by several nodes: replaced already
                albedo, ds, emission = [0.8, 0.8, 0.8], False, [0.0, 0.0, 0.0]
                if src is not None:
                    ds = not src.use_backface_culling
                    bsdf = next((n for n in src.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None) \
                        if src.use_nodes else None
                    if bsdf is not None:
                        albedo = list(bsdf.inputs["Base Color"].default_value)[:3]
                        e = bsdf.inputs["Emission"].default_value
                        s = bsdf.inputs["Emission Strength"].default_value
                        emission = [e[k] * s for k in range(3)]
                    else:
                        albedo = list(src.diffuse_color)[:3]
                if "albedo" in entry:
                    albedo = vec3(entry, "albedo")
                if "emission" in entry:
                    emission = vec3(entry, "emission")
                if "double_sided" in entry:
                    ds = bool(entry["double_sided"])
                slot.material = material("gltf%d" % index, albedo, emission, ds, bounces)
                slot.material["strahl_made"] = True


def gltf_spot_nodes(ld, inner, outer):
    # Emission strength = clamp((c - cos outer) / max(0.001, cos inner - cos
    # outer), 0, 1)^2, c = cos of the angle between the light's local -z and
    # the direction to the shaded point (Texture Coordinate Normal, the light's
    # object space, as for IES profiles).
    ld.use_nodes = True
    nt = ld.node_tree
    em = next(n for n in nt.nodes if n.type == "EMISSION")
    tc = nt.nodes.new("ShaderNodeTexCoord")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(tc.outputs["Normal"], sep.inputs[0])
    co, ci = math.cos(outer), math.cos(inner)
    lin = nt.nodes.new("ShaderNodeMath")  # (-z - co) / (ci - co) = -z k - co k
    lin.operation = "MULTIPLY_ADD"
    lin.use_clamp = True
    k = 1.0 / max(0.001, ci - co)
    nt.links.new(sep.outputs["Z"], lin.inputs[0])
    lin.inputs[1].default_value = -k
    lin.inputs[2].default_value = -co * k
    sq = nt.nodes.new("ShaderNodeMath")
    sq.operation = "MULTIPLY"
    nt.links.new(lin.outputs[0], sq.inputs[0])
    nt.links.new(lin.outputs[0], sq.inputs[1])
    nt.links.new(sq.outputs[0], em.inputs["Strength"])


def build_scene(path, opt):
    with open(path) as f:
        sc = json.load(f)
    base = os.path.dirname(os.path.abspath(path))
    # module list -> number of diffuse bounces
    bounces = 0
    for m in sc.get("modules", []):
        if m.get("name") in ("atlas_gi", "ssgi"):
            bounces = max(bounces, int(m.get("params", {}).get("bounces", 1)))
    if opt["bounces"] is not None:
        bounces = opt["bounces"]

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = opt["spp"]
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.blur_glossy = 0.0
    cy.light_sampling_threshold = 0.0
    cy.max_bounces = bounces
    cy.diffuse_bounces = bounces
    cy.glossy_bounces = 0
    cy.transmission_bounces = 0
    cy.transparent_max_bounces = 0
    cy.volume_bounces = 0
    cy.caustics_reflective = False
    cy.caustics_refractive = False
    if opt["filter"] == "box":
        cy.pixel_filter_type = "BOX"  # Cycles makes a box 1 px wide whatever the width
        cy.filter_width = 1.0
        scene.render.filter_size = 1.0
    else:
        cy.pixel_filter_type = "GAUSSIAN"
        cy.filter_width = 0.01
        scene.render.filter_size = 0.01
    cy.use_animated_seed = False
    scene.render.film_transparent = False
    scene.render.threads_mode = "FIXED"
    scene.render.threads = opt["threads"]
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.display_settings.display_device = "sRGB"

    img = sc.get("image", {})
    w, h = opt["size"] or (int(img.get("width", 512)), int(img.get("height", 512)))
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0

    # camera
    if "camera" not in sc:
        fail("%s: camera: the cross-check needs the camera in the JSON" % path)
    c = sc["camera"]
    pos, tgt, up = vec3(c, "position"), vec3(c, "target"), vec3(c, "up", [0, 1, 0])
    cam = bpy.data.cameras.new("camera")
    cam.type = "PERSP"
    cam.sensor_fit = "VERTICAL"
    cam.sensor_height = 24.0
    cam.lens = 12.0 / math.tan(math.radians(float(c["fov_y"])) / 2.0)
    cam.clip_start = 1e-5
    cam.clip_end = 1e6
    cam.shift_x = cam.shift_y = 0.0
    co = bpy.data.objects.new("camera", cam)
    scene.collection.objects.link(co)
    scene.camera = co
    from mathutils import Matrix, Vector
    P, T, U = Vector(to_blender(pos)), Vector(to_blender(tgt)), Vector(to_blender(up))
    fwd = (T - P).normalized()
    right = fwd.cross(U).normalized()
    upv = right.cross(fwd)
    M = Matrix(((right.x, upv.x, -fwd.x, P.x), (right.y, upv.y, -fwd.y, P.y),
                (right.z, upv.z, -fwd.z, P.z), (0, 0, 0, 1)))
    co.matrix_world = M

    # lights
    for i, l in enumerate(sc.get("lights", [])):
        kind = l.get("type", "point")
        if kind not in ("point", "directional", "spot"):
            fail("lights[%d].type: %s is not point, directional or spot" % (i, kind))
        if kind == "directional" and "medium" in sc:
            # strahl's sun enters the medium at the plane touching the scene's
            # bounds (docs/physics.md); a world volume would absorb it completely.
            fail("lights[%d]: a directional light in a medium is not mapped" % i)
        inten = vec3(l, "irradiance" if kind == "directional" else "intensity")
        m = max(inten)
        # A spot is a point light whose emission node applies glTF's falloff:
        # Cycles' own spot multiplies by cos(angle to the axis) and ramps by a
        # smoothstep (README.md, spot lights).
        ld = bpy.data.lights.new("light%d" % i, "SUN" if kind == "directional" else "POINT")
        if kind == "directional":
            ld.energy = m  # Cycles' sun strength is irradiance in W/m^2
            ld.angle = 0.0
        else:
            ld.shadow_soft_size = 0.0
            ld.energy = 4.0 * math.pi * m  # a spot's power is that of the point light it cuts
        if kind == "spot":
            gltf_spot_nodes(ld, math.radians(float(l.get("inner_angle", 0))),
                            math.radians(float(l.get("outer_angle", 45))))
        ld.color = [x / m for x in inten] if m > 0 else [1, 1, 1]
        ld.cycles.max_bounces = 1024
        lo = bpy.data.objects.new("light%d" % i, ld)
        if kind != "directional":
            lo.location = to_blender(vec3(l, "position"))
        if kind != "point":  # Blender's lights shine along their local -z
            from mathutils import Vector
            d = Vector(to_blender(vec3(l, "direction"))).normalized()
            lo.rotation_euler = d.to_track_quat("-Z", "Y").to_euler()
        scene.collection.objects.link(lo)

    # geometry
    for i, g in enumerate(sc.get("geometry", [])):
        albedo = vec3(g, "albedo", [0.75, 0.75, 0.75])
        emission = vec3(g, "emission", [0, 0, 0])
        ds = bool(g.get("double_sided", False))
        if "gltf" in g:
            import_gltf(os.path.join(base, g["gltf"]), g, bounces, i)
            continue
        mat = material("m%d" % i, albedo, emission, ds, bounces)
        verts, faces = [], []
        if "box" in g:
            box_faces(vec3(g["box"], "min"), vec3(g["box"], "max"), bool(g.get("inward", False)), verts, faces)
            add_mesh("box%d" % i, verts, faces, mat)
        elif "quad" in g:
            q = g["quad"]
            quad_faces(vec3(q, "corner"), vec3(q, "u"), vec3(q, "v"), verts, faces)
            add_mesh("quad%d" % i, verts, faces, mat)
        elif "sphere" in g:
            s = g["sphere"]
            v, n, f = sphere_mesh(vec3(s, "center"), float(s["radius"]), int(s.get("rings", 32)),
                                  int(s.get("segments", 64)))
            add_mesh("sphere%d" % i, v, f, mat, n)
        else:
            fail("geometry[%d]: unknown shape" % i)

    # black world, optional medium
    world = bpy.data.worlds.new("world")
    scene.world = world
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    wout = nt.nodes.new("ShaderNodeOutputWorld")
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Color"].default_value = (0, 0, 0, 1)
    bg.inputs["Strength"].default_value = 0.0
    nt.links.new(bg.outputs["Background"], wout.inputs["Surface"])
    med = sc.get("medium")
    if med and "vdb" in med.get("density", {}):
        vdb_volume(scene, base, med)
    elif med:
        ss, sa = vec3(med, "sigma_s"), vec3(med, "sigma_a")
        ph = med.get("phase", "isotropic")
        g = 0.0
        if isinstance(ph, dict) and "hg" in ph:
            g = max(-0.999, min(0.999, float(ph["hg"])))
        elif ph != "isotropic" and ph != {"isotropic": True}:
            fail("medium.phase: %r has no Cycles equivalent (isotropic and hg only)" % (ph,))
        scat = nt.nodes.new("ShaderNodeVolumeScatter")
        ds_ = max(ss)
        scat.inputs["Color"].default_value = (*[x / ds_ if ds_ > 0 else 0 for x in ss], 1)
        scat.inputs["Density"].default_value = ds_
        scat.inputs["Anisotropy"].default_value = g
        absn = nt.nodes.new("ShaderNodeVolumeAbsorption")
        da = max(sa)
        absn.inputs["Color"].default_value = (*[1 - x / da if da > 0 else 1 for x in sa], 1)
        absn.inputs["Density"].default_value = da
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(scat.outputs["Volume"], add.inputs[0])
        nt.links.new(absn.outputs["Volume"], add.inputs[1])
        nt.links.new(add.outputs["Shader"], wout.inputs["Volume"])
        world.cycles.volume_sampling = "EQUIANGULAR"
        world.cycles.homogeneous_volume = True
        if "density" in med:
            height_fog(scene, world, med["density"], scat, absn, ds_, da, opt)
    return scene, bounces


def vdb_volume(scene, base, med):
    """medium.density.vdb as a volume object with a Principled Volume (see the
    top of the file)."""
    from mathutils import Matrix, Vector
    ss, sa = vec3(med, "sigma_s"), vec3(med, "sigma_a")
    st = [a + b for a, b in zip(ss, sa)]
    if not max(st) > 0 or max(st) - min(st) > 1e-6 * max(st):
        fail("medium: a vdb density needs a grey sigma_s + sigma_a > 0 (Principled Volume's "
             "density is one number), got %s" % st)
    ph = med.get("phase", "isotropic")
    g = 0.0
    if isinstance(ph, dict) and "hg" in ph:
        g = max(-0.999, min(0.999, float(ph["hg"])))
    elif ph != "isotropic" and ph != {"isotropic": True}:
        fail("medium.phase: %r has no Cycles equivalent (isotropic and hg only)" % (ph,))
    d = med["density"]
    vol = bpy.data.volumes.new("density")
    vol.filepath = os.path.join(base, d["vdb"])
    mat = bpy.data.materials.new("density")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    pv = nt.nodes.new("ShaderNodeVolumePrincipled")
    pv.inputs["Color"].default_value = (*[x / st[0] for x in ss], 1)
    pv.inputs["Density"].default_value = st[0]
    pv.inputs["Density Attribute"].default_value = d.get("grid", "density")
    pv.inputs["Anisotropy"].default_value = g
    pv.inputs["Absorption Color"].default_value = (0, 0, 0, 1)
    nt.links.new(pv.outputs["Volume"], out.inputs["Volume"])
    mat.cycles.volume_sampling = "EQUIANGULAR"
    mat.cycles.homogeneous_volume = False
    mat.cycles.volume_interpolation = "LINEAR"
    vol.materials.append(mat)
    ob = bpy.data.objects.new("density", vol)
    scene.collection.objects.link(ob)
    tr = d.get("transform", {})
    t = [float(x) for x in tr.get("translate", [0, 0, 0])]
    k = [float(x) for x in tr.get("scale", [1, 1, 1])]
    m = Matrix(((k[0], 0, 0, t[0]), (0, k[1], 0, t[1]), (0, 0, k[2], t[2]), (0, 0, 0, 1)))
    to_z_up = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))
    # Cycles 3.4 samples a grid's voxel (i, j, k) at index coordinate
    # (i, j, k) + 0.5 (measured on this case: a half-voxel shift of the cloud
    # cut the image's rmse against toth 7x), OpenVDB and strahl at (i, j, k):
    # shift the object by half a voxel back along the grid's axes.
    vol.grids.load()
    g3 = vol.grids[d.get("grid", "density")].matrix_object.to_3x3()
    half = Matrix.Translation(g3 @ Vector((-0.5, -0.5, -0.5)))
    ob.matrix_world = to_z_up @ m @ half
    scene.cycles.volume_step_rate = 0.25
    # The grid as read, not as Blender's defaults prepare it for speed: full
    # float precision (default half) and no clipping of small densities out
    # of the volume's bounding mesh (default 0.001). Measured on vdb_cloud
    # (512 spp, with steps of 0.05 voxel): where the cloud contributes the
    # reference's mean z^2 was 0.96 against 0.99 with the defaults (README.md),
    # so these rule two suspects out rather than fix anything.
    vol.render.precision = "FULL"
    vol.render.clipping = 0.0
    # The volume's bounding mesh is a transparent surface to Cycles: with no
    # transparent bounces every path meeting it ends (the image came out
    # black). Diffuse and volume bounces stay as set.
    scene.cycles.transparent_max_bounces = 8
    scene.cycles.max_bounces = max(scene.cycles.max_bounces, 8)
    scene.cycles.volume_max_steps = 100000


def height_fog(scene, world, density, scat, absn, ds_, da, opt):
    """medium.density.height: both densities times e^(-k (y - y0)), y = Blender's
    z, from the shading point's position (Geometry.Position is the sample
    point inside a volume). Cycles 3.4 ray-marches a heterogeneous volume with
    steps of world volume_step_size (x volume_step_rate), jittered per ray:
    --volume-step sets it (default 0.02 m), far below 1/falloff so the
    marching's bias is small against the noise (README.md)."""
    if "height" not in density:
        fail("medium.density: only the height fog is mapped (not %s)" % sorted(density))
    base = float(density["height"]["base"])
    k = float(density["height"]["falloff"])
    nt = world.node_tree
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(geo.outputs["Position"], sep.inputs[0])

    def math(op, a, b=None):
        m = nt.nodes.new("ShaderNodeMath")
        m.operation = op
        m.use_clamp = False
        for i, v in enumerate((a, b)):
            if v is None:
                continue
            if isinstance(v, float):
                m.inputs[i].default_value = v
            else:
                nt.links.new(v, m.inputs[i])
        return m.outputs[0]

    d = math("EXPONENT", math("MULTIPLY", math("SUBTRACT", sep.outputs["Z"], base), -k))
    nt.links.new(math("MULTIPLY", d, float(ds_)), scat.inputs["Density"])
    nt.links.new(math("MULTIPLY", d, float(da)), absn.inputs["Density"])
    world.cycles.homogeneous_volume = False
    world.cycles.volume_step_size = opt["volume_step"]
    scene.cycles.volume_step_rate = 1.0
    scene.cycles.volume_max_steps = 100000


def render(scene, seed, path, half):
    scene.cycles.seed = seed
    s = scene.render.image_settings
    s.file_format = "OPEN_EXR"
    s.color_mode = "RGB"
    s.color_depth = "16" if half else "32"
    s.exr_codec = "ZIP"
    scene.render.filepath = path
    t0 = time.time()
    bpy.ops.render.render(write_still=True)
    return time.time() - t0


def load_rgb(path):
    im = bpy.data.images.load(path)
    im.colorspace_settings.name = "Linear"
    n = im.size[0] * im.size[1] * im.channels
    buf = array.array("f", [0.0]) * n
    im.pixels.foreach_get(buf)
    ch = im.channels
    bpy.data.images.remove(im)
    return buf, ch


def save_rgb(scene, path, rgba, w, h):
    im = bpy.data.images.new("out", w, h, alpha=False, float_buffer=True)
    im.colorspace_settings.name = "Linear"
    im.pixels.foreach_set(rgba)
    s = scene.render.image_settings
    s.file_format = "OPEN_EXR"
    s.color_mode = "RGB"
    s.color_depth = "16"
    s.exr_codec = "ZIP"
    im.save_render(path, scene=scene)
    bpy.data.images.remove(im)


def main():
    scene_path, out, opt = parse_args(sys.argv)
    scene, bounces = build_scene(scene_path, opt)
    w, h = scene.render.resolution_x, scene.render.resolution_y
    seeds = opt["seeds"]
    if len(seeds) == 1:
        t = render(scene, seeds[0], out + ".exr", not opt["float"])
        print("cycles_render: %s.exr (%dx%d, %d spp, seed %d, %d bounces, %.1f s)" %
              (out, w, h, opt["spp"], seeds[0], bounces, t))
        return
    tmp = [out + ".seed%d.tmp.exr" % s for s in seeds]
    times = [render(scene, s, p, False) for s, p in zip(seeds, tmp)]
    (a, ch), (b, _) = load_rgb(tmp[0]), load_rgb(tmp[1])
    for p in tmp:
        os.remove(p)
    n = w * h
    mean = array.array("f", [1.0]) * (4 * n)
    se = array.array("f", [1.0]) * (4 * n)
    sum_var = [0.0, 0.0, 0.0]
    sum_mean = [0.0, 0.0, 0.0]
    for i in range(n):
        for k in range(3):
            x, y = a[ch * i + k], b[ch * i + k]
            mean[4 * i + k] = 0.5 * (x + y)
            se[4 * i + k] = 0.5 * abs(x - y)
            sum_var[k] += 0.25 * (x - y) ** 2
            sum_mean[k] += 0.5 * (x + y)
    save_rgb(scene, out + ".exr", mean, w, h)
    save_rgb(scene, out + "_se.exr", se, w, h)
    rms_se = math.sqrt(sum(sum_var) / (3 * n))
    info = {
        "scene": os.path.basename(scene_path),
        "blender": bpy.app.version_string,
        "engine": "CYCLES (CPU)",
        "width": w, "height": h, "spp": opt["spp"], "seeds": seeds, "threads": opt["threads"],
        "diffuse_bounces": bounces, "volume_bounces": 0,
        "pixel_filter": "box, 1 px (mean over the pixel)" if opt["filter"] == "box"
                        else "gaussian, 0.01 px (pixel centres)",
        "render_seconds": [round(t, 2) for t in times],
        "image_mean": [round(x / n, 6) for x in sum_mean],
        "rms_standard_error_of_mean": rms_se,
        "relative_rms_standard_error": rms_se / max(1e-30, sum(sum_mean) / (3 * n)),
        "files": {"mean": os.path.basename(out) + ".exr",
                  "standard_error": os.path.basename(out) + "_se.exr"},
    }
    with open(out + ".json", "w") as f:
        json.dump(info, f, indent=1)
        f.write("\n")
    print("cycles_render: %s.exr (%dx%d, %d spp, seeds %s, %d bounces, %.1f s + %.1f s)" %
          (out, w, h, opt["spp"], seeds, bounces, times[0], times[1]))


main()
