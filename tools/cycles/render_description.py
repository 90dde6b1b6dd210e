# Renders an mrgi scene description (tools/reference/include/mrgi/reference/description.h) with
# Blender Cycles, as an independent check on mrgi's own path tracer (docs/DESIGN.md "Ground truth and
# error"). Run:
#
#   blender -b --factory-startup -noaudio -P tools/cycles/render_description.py -- \
#       DESCRIPTION.json OUTDIR [--frames N] [--spp S] [--threads T] [--seed K]
#
# (--seed overrides render.seed, e.g. for a second render of frame 0 that measures the noise floor.)
# Per frame f (time f / fps, as mrgi synth) it writes linear-radiance float OpenEXR files
# OUTDIR/NNNNNN_<what>.exr, all at the colour camera's size unless said otherwise:
#   C       the camera view of the real scene (virtual objects hidden), linear radiance
#   G       the same with the virtual objects, same seed (Cycles' samples are a function of seed,
#           pixel and sample, so paths that never meet a virtual object repeat in G)
#   depth   metres along the camera's optical axis of the real scene's pixel-centre ray, in every
#           channel; 0 = no hit
#   normal  0.5 + 0.5 n, n the real scene's unit surface normal at that ray's hit, world axes of
#           mrgi (y up), so the converter can find the incidence angle (EXR readers in mrgi clamp
#           negative values, hence the offset)
#   mask    1 where the pixel-centre ray of the scene with the virtual objects meets one first
#   env     the env camera's equidistant fisheye (env_camera.size squared, real scene only), when
#           the description has one
# and OUTDIR/renders.json (settings, Blender version, seconds per frame). Frames whose files all
# exist are skipped, so an interrupted run goes on where it stopped.
# `mrgi synth DESCRIPTION.json --from-renders OUTDIR --out CAPTURE` turns them into a capture.
#
# Conventions (mrgi on the left, Blender/Cycles on the right) and how each is mapped:
#  * World axes: mrgi is y up (glTF); Blender is z up. A point (x, y, z) of mrgi is Blender
#    (x, -z, y) (matrix B below), the glTF importer's own mapping, so imported models and
#    generated shapes agree. Every placement M of mrgi becomes B M B^-1 in Blender.
#  * Camera: mrgi is OpenCV (x right, y down, looking along +z, camera-to-world poses from
#    position/look_at/up as mrgi's look_rotation); a Blender camera looks along its -z with y up,
#    so its rotation is mrgi's times diag(1, -1, -1).
#  * Intrinsics: sensor_fit HORIZONTAL, sensor_width = image width and lens = fx (both read as
#    "mm", so fx is in pixels); Cycles has one focal length, so fx must equal fy. mrgi's integer
#    pixel coordinates are pixel centres (cx = 319.5 is the centre of a 640-wide image), Blender's
#    principal point is at width / 2 in continuous coordinates shifted by shift_x * max(w, h):
#    shift_x = (w / 2 - (cx + 0.5)) / max(w, h), shift_y = ((cy + 0.5) - h / 2) / max(w, h)
#    (Blender's y is up, the image's down).
#  * Pixel filter: mrgi jitters uniformly over the pixel (box, 1 px); Cycles is set to BOX 1 px.
#    Depth, normal and mask are rendered at 1 sample with a 0.01 px box, i.e. at the pixel centre,
#    as mrgi's ideal depth and mask are.
#  * Point and spot lamps: mrgi's intensity * color is radiant intensity in W/sr per channel.
#    Cycles' point and spot lamps of `energy` P emit P / (4 pi) W/sr (checked: a 1 W/sr lamp 1 m
#    above a white Lambertian floor gives radiance 1/pi there; perf/cycles/README.md), so
#    energy = 4 pi * max channel and color = channel / max channel. Radius (shadow_soft_size) 0:
#    mrgi's lamps are points.
#  * Spot cone: mrgi's falloff is smoothstep(cos outer, cos inner, cos angle) on the cosine of
#    the angle to the axis. Cycles 3.4's is cos(angle) * smoothstep(0, 1, (cos angle - cos half)
#    / ((1 - cos half) * blend)) with spot_size the FULL cone angle: so spot_size = 2 * outer and
#    spot_blend = (cos inner - cos outer) / (1 - cos outer) give the same smoothstep, and the extra
#    cos(angle) factor (mrgi has none) is divided out in the lamp's node tree: emission strength
#    1 / |n.z|, n the texture-coordinate Normal, which for a lamp is the direction from the lamp in
#    its own axes (its axis is -z).
#  * Directional lamps: mrgi's intensity is irradiance in W/m^2, as Cycles' sun strength; angle 0.
#  * Area lamps: mrgi's are one-sided emissive rectangles of radiance `intensity` * color; here an
#    emissive plane (Cycles' mesh emission of strength 1 has radiance = color) that is black from
#    behind. Not checked against mrgi yet (no suite scene has one).
#  * Environment: mrgi maps an environment-space direction d (y up) to u = 0.5 + atan2(d.x, -d.z)
#    / 2pi, v = acos(d.y) / pi (v down, image centre looking along -z), rotated by
#    environment.rotation (environment to world) and scaled by intensity. Cycles' equirectangular
#    lookup of a Blender direction V is u = 0.5 - atan2(V.y, V.x) / 2pi, v (up) = 0.5 +
#    asin(V.z) / pi, so the world texture is fed V = A R^T B^-1 D with A d = (-d.z, -d.x, d.y)
#    (D the world direction in Blender axes); background strength = intensity. The procedural sky
#    ("environment.sky") is built as a world shader of the same formula (build_sky), its sun an
#    analytic disc carrying sun_irradiance, sampled through a 2048-wide importance map.
#  * Materials (mrgi's bsdf.h): diffuse -> Diffuse BSDF, roughness 0 (Lambert, as mrgi);
#    glossy -> Diffuse BSDF (Lambert) of base * (1 - metallic) * 0.96 plus a Principled BSDF
#    used as a pure GGX lobe (metallic 1, base colour = F0 = mix(0.04, base, metallic),
#    single-scattering GGX as mrgi, alpha = roughness^2 in both). Principled's own diffuse lobe
#    is Disney's (retro-reflection growing with roughness), not mrgi's Lambert * 0.96, so it is
#    not used. Left different: Principled's metallic Fresnel goes from F0 to white along a
#    dielectric Fresnel curve, close to but not Schlick's. mirror -> Glossy BSDF SHARP with the base colour (constant reflectance, as
#    mrgi). glass -> Glass BSDF SHARP with ior and the base colour (Cycles tints the reflection
#    too, mrgi only the transmission). emission -> added Emission of strength 1 (radiance),
#    front face only as mrgi.
#  * glTF materials are rebuilt with mrgi's rule (synth_scene.cpp from_gltf): transmission >= 0.5
#    glass, metallic >= 0.99 and roughness <= 0.02 mirror, metallic 0 and roughness 1 diffuse,
#    else glossy, keeping the importer's base colour texture. Imported objects take their placement
#    as a matrix (the importer sets quaternion rotation mode, so Euler angles would do nothing).
#  * Bounces: mrgi's max_depth counts indirect bounces (0 = direct light only) as Cycles'
#    max_bounces; every per-type limit is set to it. Cycles' defaults that bias or decorrelate
#    are off: adaptive sampling, denoising, sample clamping, glossy filter, path guiding,
#    animated seed. Russian roulette differs (unbiased in both).
#  * Colour: Blender's scene-linear space is linear Rec.709/sRGB primaries, as mrgi's linear
#    RGB. View transform Standard, exposure 0, gamma 1; the EXRs are written as scene-linear
#    floats anyway. mrgi's camera `exposure` (and the sRGB curve, sensor noise, Kinect depth
#    model) is applied by the converter, not here.
#  * Camera noise and the Kinect-like depth are applied by the converter (mrgi's sensor models).
import json
import math
import os
import sys
import time

import bpy
from mathutils import Matrix, Quaternion, Vector

try:
    # Blender 3.4's glTF importer uses numpy.bool, which numpy 1.24 (Debian 12's python3-numpy,
    # which the importer needs) removed; it meant the builtin bool.
    import numpy
    if "bool" not in numpy.__dict__:
        numpy.bool = bool
except ImportError:
    pass

B = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))  # mrgi world -> Blender world
B_INV = B.inverted()


def fail(msg):
    print("render_description: " + msg, file=sys.stderr)
    sys.exit(2)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    opts = {"frames": None, "spp": None, "threads": 0, "seed": None}
    pos = []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("--frames", "--spp", "--threads", "--seed"):
            if i + 1 >= len(argv):
                fail(a + " needs a value")
            try:
                opts[a[2:]] = int(argv[i + 1])
            except ValueError:
                fail(a + " must be an integer")
            i += 2
        else:
            pos.append(a)
            i += 1
    if len(pos) != 2:
        fail("usage: blender -b --factory-startup -noaudio -P render_description.py -- "
             "DESCRIPTION.json OUTDIR [--frames N] [--spp S] [--threads T] [--seed K]")
    return pos[0], pos[1], opts


# ---- description (defaults as tools/reference/src/description.cpp) ---------------------------

def vec(v, default):
    return Vector(v if v is not None else default)


def quat_xyzw(q):
    if q is None:
        return Quaternion((1, 0, 0, 0))
    return Quaternion((q[3], q[0], q[1], q[2])).normalized()


def placement_matrix(o):
    return (Matrix.Translation(vec(o.get("position"), (0, 0, 0))) @ quat_xyzw(o.get("rotation")).to_matrix().to_4x4()
            @ Matrix.Scale(o.get("scale", 1.0), 4))


def look_rotation(position, look_at, up):
    # mrgi's look_rotation (description.cpp): OpenCV axes, columns x right, y down, z forward.
    z = (look_at - position).normalized()
    x = z.cross(up).normalized()
    y = z.cross(x)
    return Matrix((x, y, z)).transposed()


def camera_pose_at(desc, t):
    keys = desc["camera_path"]

    def key(k):
        return (vec(k.get("position"), (0, 0, 0)), vec(k.get("look_at"), (0, 0, 1)), vec(k.get("up"), (0, 1, 0)))

    if t >= keys[-1].get("time", 0.0):
        p, l, u = key(keys[-1])
    elif t <= keys[0].get("time", 0.0):
        p, l, u = key(keys[0])
    else:
        i = 1
        while keys[i]["time"] < t:
            i += 1
        a, b = key(keys[i - 1]), key(keys[i])
        s = (t - keys[i - 1]["time"]) / (keys[i]["time"] - keys[i - 1]["time"])
        p = a[0].lerp(b[0], s)
        l = a[1].lerp(b[1], s)
        u = a[2].lerp(b[2], s).normalized()
        fwd = l - p
        if fwd.length <= 1e-9 or fwd.normalized().cross(u).length <= 1e-6:
            l = p + (a[1] - a[0])
            u = a[2]
    return p, look_rotation(p, l, u)


def opencv_to_blender_camera(position, rot_cv):
    # Blender's camera looks along its -z with y up: flip y and z of the OpenCV axes.
    m = (rot_cv @ Matrix(((1, 0, 0), (0, -1, 0), (0, 0, -1)))).to_4x4()
    m.translation = position
    return B @ m


# ---- scene building --------------------------------------------------------------------------

def clear_scene():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.lights, bpy.data.cameras, bpy.data.materials):
        for d in list(coll):
            coll.remove(d)


def new_material(name, m, emission_front_only=True):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    t = m.get("type", "diffuse")
    color = tuple(m.get("color", (0.8, 0.8, 0.8))) + (1.0,)
    if t == "diffuse":
        s = nt.nodes.new("ShaderNodeBsdfDiffuse")
        s.inputs["Color"].default_value = color
        s.inputs["Roughness"].default_value = 0.0  # Lambert
        color_in = s.inputs["Color"]
    elif t == "glossy":
        # mrgi's glossy (bsdf.h): Lambert of base * (1 - metallic) * 0.96 plus a GGX lobe with
        # F0 = mix(0.04, base, metallic). Principled's own diffuse lobe is Disney's (brighter, with
        # retro-reflection), so the Lambert part is a Diffuse BSDF and the Principled BSDF is used
        # as a pure GGX lobe: metallic 1 makes its base colour the F0 (Fresnel towards white at
        # grazing angles, close to Schlick) and switches its diffuse off.
        metal = m.get("metallic", 0.0)
        d = nt.nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Roughness"].default_value = 0.0
        p = nt.nodes.new("ShaderNodeBsdfPrincipled")
        p.distribution = "GGX"
        p.inputs["Metallic"].default_value = 1.0
        p.inputs["Roughness"].default_value = m.get("roughness", 0.5)
        p.inputs["Specular"].default_value = 0.5
        rgb = nt.nodes.new("ShaderNodeRGB")
        rgb.outputs[0].default_value = color
        diff_w = nt.nodes.new("ShaderNodeMixRGB")  # base * (1 - metallic) * 0.96
        diff_w.blend_type = "MULTIPLY"
        diff_w.inputs["Fac"].default_value = 1.0
        diff_w.inputs["Color2"].default_value = ((1.0 - metal) * 0.96,) * 3 + (1.0,)
        f0 = nt.nodes.new("ShaderNodeMixRGB")  # mix(0.04, base, metallic)
        f0.blend_type = "MIX"
        f0.inputs["Fac"].default_value = metal
        f0.inputs["Color1"].default_value = (0.04, 0.04, 0.04, 1.0)
        nt.links.new(diff_w.outputs[0], d.inputs["Color"])
        nt.links.new(f0.outputs[0], p.inputs["Base Color"])
        s = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(d.outputs[0], s.inputs[0])
        nt.links.new(p.outputs[0], s.inputs[1])
        # The base colour (or a texture linked in by rebuild_gltf_material) feeds both weights.
        reroute = nt.nodes.new("NodeReroute")
        nt.links.new(rgb.outputs[0], reroute.inputs[0])
        nt.links.new(reroute.outputs[0], diff_w.inputs["Color1"])
        nt.links.new(reroute.outputs[0], f0.inputs["Color2"])
        color_in = reroute.inputs[0]
    elif t == "mirror":
        s = nt.nodes.new("ShaderNodeBsdfGlossy")
        s.distribution = "SHARP"
        s.inputs["Color"].default_value = color
        color_in = s.inputs["Color"]
    elif t == "glass":
        s = nt.nodes.new("ShaderNodeBsdfGlass")
        s.distribution = "SHARP"
        s.inputs["Color"].default_value = color
        s.inputs["IOR"].default_value = m.get("ior", 1.5)
        color_in = s.inputs["Color"]
    else:
        fail("material type '%s' is not one of diffuse, glossy, mirror, glass" % t)
    shader = s.outputs[0]
    em = m.get("emission", (0, 0, 0))
    if max(em) > 0:
        e = nt.nodes.new("ShaderNodeEmission")
        e.inputs["Color"].default_value = tuple(em) + (1.0,)
        e.inputs["Strength"].default_value = 1.0  # mesh emission: radiance = colour * strength
        add = nt.nodes.new("ShaderNodeAddShader")
        em_out = e.outputs[0]
        if emission_front_only:
            geo = nt.nodes.new("ShaderNodeNewGeometry")
            mix = nt.nodes.new("ShaderNodeMixShader")
            nt.links.new(geo.outputs["Backfacing"], mix.inputs[0])
            nt.links.new(e.outputs[0], mix.inputs[1])  # front: emission; back: nothing
            em_out = mix.outputs[0]
        nt.links.new(shader, add.inputs[0])
        nt.links.new(em_out, add.inputs[1])
        shader = add.outputs[0]
    nt.links.new(shader, out.inputs["Surface"])
    return mat, color_in


def mesh_object(name, verts, faces, smooth, material):
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(B @ Vector(v)) for v in verts], [], faces)
    me.update()
    for p in me.polygons:
        p.use_smooth = smooth
    me.materials.append(material)
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def transform_points(points, m):
    return [tuple(m @ Vector(p)) for p in points]


def shape_geometry(o):
    # The same tessellation as tools/reference/src/shapes.cpp, in the object's local axes.
    shape = o["shape"]
    if shape == "plane":
        hx, hz = 0.5 * o["size"][0], 0.5 * o["size"][1]
        return [(-hx, 0, hz), (hx, 0, hz), (hx, 0, -hz), (-hx, 0, -hz)], [(0, 1, 2, 3)], False
    if shape == "box":
        h = [0.5 * s for s in o["size"]]
        verts, faces = [], []
        for axis in range(3):
            for sign in (-1, 1):
                a1, a2 = (axis + 1) % 3, (axis + 2) % 3
                u = [0, 0, 0]; v = [0, 0, 0]; c = [0, 0, 0]
                u[a1] = h[a1]; v[a2] = h[a2]; c[axis] = sign * h[axis]
                U, V, C = Vector(u), Vector(v), Vector(c)
                quad = [C - U - V, C + U - V, C + U + V, C - U + V] if sign > 0 else [C - U - V, C - U + V, C + U + V, C + U - V]
                b = len(verts)
                verts += [tuple(q) for q in quad]
                faces.append((b, b + 1, b + 2, b + 3))
        return verts, faces, False
    if shape == "sphere":
        r, segments = o["radius"], 64
        rings = segments // 2
        verts, faces = [], []
        for ri in range(rings + 1):
            th = math.pi * ri / rings
            for si in range(segments + 1):
                ph = 2 * math.pi * si / segments
                verts.append((r * math.sin(th) * math.cos(ph), r * math.cos(th), -r * math.sin(th) * math.sin(ph)))
        row = segments + 1
        for ri in range(rings):
            for si in range(segments):
                a = ri * row + si
                b = a + row
                if ri != 0:
                    faces.append((a, b, a + 1))
                if ri != rings - 1:
                    faces.append((a + 1, b, b + 1))
        return verts, faces, True
    fail("real_objects shape '%s' is not built here" % shape)


def rebuild_gltf_material(mat):
    # mrgi's from_gltf rule (synth_scene.cpp) on what Blender's importer made of the glTF material.
    nt = mat.node_tree
    p = next((n for n in nt.nodes if n.type == "BSDF_PRINCIPLED"), None)
    if p is None:
        return
    base = p.inputs["Base Color"]
    color = list(base.default_value)[:3]
    link = base.links[0].from_socket if base.is_linked else None
    rough = p.inputs["Roughness"].default_value if not p.inputs["Roughness"].is_linked else 0.5
    metal = p.inputs["Metallic"].default_value if not p.inputs["Metallic"].is_linked else 0.0
    trans = p.inputs["Transmission"].default_value
    ior = p.inputs["IOR"].default_value
    emission = list(p.inputs["Emission"].default_value)[:3] if not p.inputs["Emission"].is_linked else [0, 0, 0]
    strength = p.inputs["Emission Strength"].default_value
    if trans >= 0.5:
        t = "glass"
    elif metal >= 0.99 and rough <= 0.02:
        t = "mirror"
    elif metal <= 0.0 and rough >= 1.0:
        t = "diffuse"
    else:
        t = "glossy"
    desc = {"type": t, "color": [min(max(c, 0), 1) for c in color], "roughness": rough, "metallic": metal, "ior": ior,
            "emission": [max(e * strength, 0) for e in emission]}
    new, color_in = new_material(mat.name + "_mrgi", desc)
    if link is not None:
        # Carry the texture (and the importer's factor multiply) over into the new tree.
        src_node = link.node
        copied = {}

        def copy(n):
            if n.name in copied:
                return copied[n.name]
            c = new.node_tree.nodes.new(n.bl_idname)
            for attr in ("image", "interpolation", "projection", "extension", "blend_type", "data_type", "operation",
                         "uv_map", "vector_type"):
                if hasattr(n, attr):
                    try:
                        setattr(c, attr, getattr(n, attr))
                    except (AttributeError, TypeError):
                        pass
            for i, inp in enumerate(n.inputs):
                if hasattr(inp, "default_value"):
                    try:
                        c.inputs[i].default_value = inp.default_value
                    except (AttributeError, TypeError, ValueError):
                        pass
                for l in inp.links:
                    new.node_tree.links.new(copy(l.from_node).outputs[l.from_socket.identifier], c.inputs[i])
            copied[n.name] = c
            return c

        new.node_tree.links.new(copy(src_node).outputs[link.identifier], color_in)
    return new


def import_gltf(path, name):
    before = set(bpy.data.objects)
    bpy.ops.import_scene.gltf(filepath=path)
    objs = [o for o in bpy.data.objects if o not in before]
    for o in objs:
        if o.type in ("LIGHT", "CAMERA"):
            bpy.data.objects.remove(o, do_unlink=True)
    objs = [o for o in bpy.data.objects if o not in before]
    done = {}
    for o in objs:
        if o.type == "MESH":
            for slot in o.material_slots:
                if slot.material is not None:
                    if slot.material.name not in done:
                        done[slot.material.name] = rebuild_gltf_material(slot.material) or slot.material
                    slot.material = done[slot.material.name]
    root = bpy.data.objects.new(name, None)
    bpy.context.scene.collection.objects.link(root)
    for o in objs:
        if o.parent is None:
            o.parent = root
    return root, [o for o in objs if o.type == "MESH"]


def lamp_object(i, l):
    t = l.get("type", "point")
    color = [c * l.get("intensity", 1.0) for c in l.get("color", (1, 1, 1))]
    peak = max(color)
    if t == "area":
        w, h = l.get("size", (0.2, 0.2))
        desc = {"type": "diffuse", "color": [0, 0, 0], "emission": color}
        mat, _ = new_material("lamp%d" % i, desc)
        d = vec(l.get("direction"), (0, -1, 0)).normalized()
        rot = Vector((0, 1, 0)).rotation_difference(d).to_matrix().to_4x4()
        m = Matrix.Translation(vec(l.get("position"), (0, 0, 0))) @ rot
        verts, faces, _ = shape_geometry({"shape": "plane", "size": [w, h]})
        return mesh_object("lamp%d" % i, transform_points(verts, m), faces, False, mat)
    kind = {"point": "POINT", "spot": "SPOT", "directional": "SUN"}[t]
    data = bpy.data.lights.new("lamp%d" % i, kind)
    data.color = [c / peak for c in color] if peak > 0 else (1, 1, 1)
    if kind == "SUN":
        data.energy = peak  # W/m^2
        data.angle = 0.0
    else:
        data.energy = 4.0 * math.pi * peak  # Cycles: I = P / (4 pi) W/sr
        data.shadow_soft_size = 0.0
    data.cycles.cast_shadow = True
    if kind == "SPOT":
        inner = math.radians(l.get("inner_angle_deg", 30.0))
        outer = math.radians(l.get("outer_angle_deg", 45.0))
        data.spot_size = 2.0 * outer
        data.spot_blend = max(0.0, (math.cos(inner) - math.cos(outer)) / (1.0 - math.cos(outer)))
        # Divide out Cycles' extra cos(angle to the axis): strength 1 / |normal.z| in lamp axes.
        data.use_nodes = True
        nt = data.node_tree
        em = next(n for n in nt.nodes if n.type == "EMISSION")
        tc = nt.nodes.new("ShaderNodeTexCoord")
        sep = nt.nodes.new("ShaderNodeSeparateXYZ")
        ab = nt.nodes.new("ShaderNodeMath"); ab.operation = "ABSOLUTE"
        mx = nt.nodes.new("ShaderNodeMath"); mx.operation = "MAXIMUM"; mx.inputs[1].default_value = 1e-4
        dv = nt.nodes.new("ShaderNodeMath"); dv.operation = "DIVIDE"; dv.inputs[0].default_value = 1.0
        nt.links.new(tc.outputs["Normal"], sep.inputs[0])
        nt.links.new(sep.outputs["Z"], ab.inputs[0])
        nt.links.new(ab.outputs[0], mx.inputs[0])
        nt.links.new(mx.outputs[0], dv.inputs[1])
        nt.links.new(dv.outputs[0], em.inputs["Strength"])
    ob = bpy.data.objects.new("lamp%d" % i, data)
    bpy.context.scene.collection.objects.link(ob)
    m = Matrix.Identity(4)
    if kind in ("SPOT", "SUN"):
        d = vec(l.get("direction"), (0, -1, 0)).normalized()
        m = Vector((0, 0, -1)).rotation_difference(d).to_matrix().to_4x4()  # Blender lamps shine along -z
    m.translation = vec(l.get("position"), (0, 0, 0))
    ob.matrix_world = B @ m
    return ob


def env_axis_node(nt, tc, row):
    """A node whose value is row . (R^T B^-1 D): one environment-space component of the world
    direction D (Blender axes) the world shader is evaluated for."""
    dot = nt.nodes.new("ShaderNodeVectorMath")
    dot.operation = "DOT_PRODUCT"
    dot.inputs[1].default_value = tuple(row)
    nt.links.new(tc.outputs["Generated"], dot.inputs[0])
    return dot.outputs["Value"]


def build_sky(nt, bg, env):
    """mrgi's procedural sky (description.h ProceduralSky) as a world shader: radiance horizon +
    (zenith - horizon) sqrt(y) above the horizon and `ground` below (y the environment-space up
    component), plus an analytic sun disc of sun_radius_deg whose uniform radiance carries
    sun_irradiance (mrgi rasterises the same disc into an equirect image whose disc pixels carry
    it; here the disc is exact, so the two differ only in the disc's outline). The world's
    importance map is made fine enough (2048 wide) that the disc is sampled as a light."""
    sky = env["sky"]
    r = quat_xyzw(env.get("rotation")).to_matrix()
    k = r.transposed() @ B_INV.to_3x3()  # Blender direction -> environment space (mrgi axes)
    tc = nt.nodes.new("ShaderNodeTexCoord")
    y = env_axis_node(nt, tc, k[1])
    up = nt.nodes.new("ShaderNodeMath")
    up.operation = "GREATER_THAN"
    up.inputs[1].default_value = 0.0
    nt.links.new(y, up.inputs[0])
    root = nt.nodes.new("ShaderNodeMath")  # sqrt(max(y, 0))
    root.operation = "POWER"
    root.use_clamp = False
    clampy = nt.nodes.new("ShaderNodeMath")
    clampy.operation = "MAXIMUM"
    clampy.inputs[1].default_value = 0.0
    nt.links.new(y, clampy.inputs[0])
    nt.links.new(clampy.outputs[0], root.inputs[0])
    root.inputs[1].default_value = 0.5

    def rgb_mix(fac, a, b):
        m = nt.nodes.new("ShaderNodeMixRGB")
        m.blend_type = "MIX"
        nt.links.new(fac, m.inputs["Fac"])
        for slot, v in (("Color1", a), ("Color2", b)):
            if isinstance(v, (list, tuple)):
                m.inputs[slot].default_value = (v[0], v[1], v[2], 1.0)
            else:
                nt.links.new(v, m.inputs[slot])
        return m.outputs["Color"]

    gradient = rgb_mix(root.outputs[0], sky.get("horizon", [0.12, 0.15, 0.20]), sky.get("zenith", [0.05, 0.09, 0.20]))
    g = sky.get("ground", [0.03, 0.03, 0.03])
    if not isinstance(g, (list, tuple)):
        g = [g, g, g]
    base = rgb_mix(up.outputs[0], g, gradient)
    # Sun disc: cos(angle to the sun) >= cos(radius) adds irradiance / (disc solid angle).
    sun = Vector(sky.get("sun_direction", [0, 1, 0])).normalized()
    radius = math.radians(sky.get("sun_radius_deg", 2.0))
    solid = 2.0 * math.pi * (1.0 - math.cos(radius))
    irr = sky.get("sun_irradiance", [3, 3, 3])
    if not isinstance(irr, (list, tuple)):
        irr = [irr, irr, irr]
    row = Vector((sun.x * k[0][0] + sun.y * k[1][0] + sun.z * k[2][0],
                  sun.x * k[0][1] + sun.y * k[1][1] + sun.z * k[2][1],
                  sun.x * k[0][2] + sun.y * k[1][2] + sun.z * k[2][2]))  # k^T sun: dot(sun, k D)
    cosang = env_axis_node(nt, tc, row)
    inside = nt.nodes.new("ShaderNodeMath")
    inside.operation = "GREATER_THAN"
    inside.inputs[1].default_value = math.cos(radius)
    nt.links.new(cosang, inside.inputs[0])
    disc = nt.nodes.new("ShaderNodeMixRGB")
    disc.blend_type = "ADD"
    nt.links.new(inside.outputs[0], disc.inputs["Fac"])
    nt.links.new(base, disc.inputs["Color1"])
    disc.inputs["Color2"].default_value = (irr[0] / solid, irr[1] / solid, irr[2] / solid, 1.0)
    nt.links.new(disc.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = env.get("intensity", 1.0)
    w = bpy.context.scene.world
    if hasattr(w, "cycles"):
        w.cycles.sampling_method = "MANUAL"
        w.cycles.sample_map_resolution = 2048


def build_world(desc, base):
    world = bpy.data.worlds.new("mrgi")
    bpy.context.scene.world = world
    world.use_nodes = True
    nt = world.node_tree
    bg = next(n for n in nt.nodes if n.type == "BACKGROUND")
    env = desc.get("environment")
    if not env:
        bg.inputs["Color"].default_value = (0, 0, 0, 1)  # factory world is 0.05 grey
        bg.inputs["Strength"].default_value = 0.0
        return
    if "sky" in env:
        build_sky(nt, bg, env)
        return
    tex = nt.nodes.new("ShaderNodeTexEnvironment")
    tex.image = bpy.data.images.load(os.path.join(base, env["image"]))
    tex.image.colorspace_settings.name = "Linear"
    tex.interpolation = "Linear"
    bg.inputs["Strength"].default_value = env.get("intensity", 1.0)
    # V = A R^T B^-1 D (header): three dot products of the world direction D.
    r = quat_xyzw(env.get("rotation")).to_matrix()
    a = Matrix(((0, 0, -1), (-1, 0, 0), (0, 1, 0)))
    k = a @ r.transposed() @ B_INV.to_3x3()
    tc = nt.nodes.new("ShaderNodeTexCoord")
    comb = nt.nodes.new("ShaderNodeCombineXYZ")
    for i, axis in enumerate("XYZ"):
        dot = nt.nodes.new("ShaderNodeVectorMath")
        dot.operation = "DOT_PRODUCT"
        dot.inputs[1].default_value = tuple(k[i])
        nt.links.new(tc.outputs["Generated"], dot.inputs[0])
        nt.links.new(dot.outputs["Value"], comb.inputs[axis])
    nt.links.new(comb.outputs[0], tex.inputs["Vector"])
    nt.links.new(tex.outputs["Color"], bg.inputs["Color"])


# ---- rendering -------------------------------------------------------------------------------

def setup_render(desc, spp, threads, seed):
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    cy = sc.cycles
    cy.device = "CPU"
    cy.samples = spp
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.blur_glossy = 0.0
    cy.caustics_reflective = True
    cy.caustics_refractive = True
    if hasattr(cy, "use_guiding"):
        cy.use_guiding = False
    cy.seed = int(seed if seed is not None else desc.get("render", {}).get("seed", 1)) % (1 << 31)
    cy.use_animated_seed = False
    depth = int(desc.get("render", {}).get("max_depth", 6))
    cy.max_bounces = depth
    cy.diffuse_bounces = depth
    cy.glossy_bounces = depth
    cy.transmission_bounces = depth
    cy.volume_bounces = 0
    cy.transparent_max_bounces = 8
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.film_exposure = 1.0
    sc.render.film_transparent = False
    sc.view_settings.view_transform = "Standard"
    sc.view_settings.look = "None"
    sc.view_settings.exposure = 0.0
    sc.view_settings.gamma = 1.0
    sc.render.resolution_percentage = 100
    sc.render.use_persistent_data = True
    if threads > 0:
        sc.render.threads_mode = "FIXED"
        sc.render.threads = threads
    vl = bpy.context.view_layer
    vl.use_pass_z = True
    vl.use_pass_normal = True
    vl.use_pass_object_index = True
    sc.use_nodes = True
    nt = sc.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    rl = nt.nodes.new("CompositorNodeRLayers")
    fo = nt.nodes.new("CompositorNodeOutputFile")
    fo.format.file_format = "OPEN_EXR"
    fo.format.color_depth = "32"
    fo.format.color_mode = "RGB"
    fo.format.exr_codec = "ZIP"
    comp = nt.nodes.new("CompositorNodeComposite")
    nt.links.new(rl.outputs["Image"], comp.inputs["Image"])
    # Normal -> 0.5 + 0.5 n in mrgi axes (x, y, z) = Blender (X, Z, -Y).
    sep = nt.nodes.new("CompositorNodeSeparateXYZ")
    comb = nt.nodes.new("CompositorNodeCombineXYZ")
    nt.links.new(rl.outputs["Normal"], sep.inputs[0])
    for src, dst, sign in (("X", "X", 1), ("Z", "Y", 1), ("Y", "Z", -1)):
        m = nt.nodes.new("CompositorNodeMath")
        m.operation = "MULTIPLY_ADD"
        m.inputs[1].default_value = 0.5 * sign
        m.inputs[2].default_value = 0.5
        nt.links.new(sep.outputs[src], m.inputs[0])
        nt.links.new(m.outputs[0], comb.inputs[dst])
    # Depth: Cycles writes 1e10 where the ray hits nothing; mrgi's 0 = no hit.
    lt = nt.nodes.new("CompositorNodeMath"); lt.operation = "LESS_THAN"; lt.inputs[1].default_value = 1e6
    mul = nt.nodes.new("CompositorNodeMath"); mul.operation = "MULTIPLY"
    nt.links.new(rl.outputs["Depth"], lt.inputs[0])
    nt.links.new(rl.outputs["Depth"], mul.inputs[0])
    nt.links.new(lt.outputs[0], mul.inputs[1])
    return {"rl": rl, "fo": fo, "normal": comb.outputs[0], "depth": mul.outputs[0], "nt": nt}


def render_to(outputs, comp, outdir, frame, samples, filter_width):
    """Renders the current scene once and writes OUTPUTS ({suffix: socket name or socket})."""
    sc = bpy.context.scene
    sc.cycles.samples = samples
    sc.cycles.filter_width = filter_width
    fo, nt = comp["fo"], comp["nt"]
    fo.base_path = outdir
    fo.file_slots.clear()
    for suffix, src in outputs.items():
        fo.file_slots.new("tmp_%s_" % suffix)
        sock = comp["rl"].outputs[src] if isinstance(src, str) else src
        nt.links.new(sock, fo.inputs[-1])
    sc.frame_current = 0
    bpy.ops.render.render(write_still=False)
    for suffix in outputs:
        src = os.path.join(outdir, "tmp_%s_0000.exr" % suffix)
        if not os.path.exists(src):
            fail("Blender did not write %s" % src)
        os.replace(src, os.path.join(outdir, "%06d_%s.exr" % (frame, suffix)))


def main():
    desc_path, outdir, opts = parse_args()
    with open(desc_path) as f:
        desc = json.load(f)
    base = os.path.dirname(os.path.abspath(desc_path))
    frames = opts["frames"] or desc.get("frames", 8)
    spp = opts["spp"] or desc.get("render", {}).get("spp", 64)
    fps = desc.get("fps", 30.0)
    os.makedirs(outdir, exist_ok=True)
    outdir = os.path.abspath(outdir)

    clear_scene()
    sc = bpy.context.scene
    comp = setup_render(desc, spp, opts["threads"], opts["seed"])
    for i, o in enumerate(desc.get("real_objects", [])):
        if o["shape"] == "gltf":
            root, meshes = import_gltf(os.path.join(base, o["gltf"]), "real%d" % i)
            if "material" in o:
                mat, _ = new_material("real%d" % i, o["material"])
                for ob in meshes:
                    ob.data.materials.clear()
                    ob.data.materials.append(mat)
            root.matrix_world = B @ placement_matrix(o) @ B_INV
            continue
        verts, faces, smooth = shape_geometry(o)
        mat, _ = new_material("real%d" % i, o["material"])
        mesh_object("real%d" % i, transform_points(verts, placement_matrix(o)), faces, smooth, mat)
    for i, l in enumerate(desc.get("lights", [])):
        if not l.get("real", True):
            fail("lights[%d]: virtual lamps are not built here (C and G would differ by them)" % i)
        lamp_object(i, l)
    build_world(desc, base)
    virtual = []
    for i, v in enumerate(desc.get("virtual_objects", [])):
        root, meshes = import_gltf(os.path.join(base, v["gltf"]), "virtual%d" % i)
        for ob in meshes:
            ob.pass_index = 1
        virtual.append((v, root, [root] + meshes))

    cam_desc = desc["camera"]
    w, h = cam_desc.get("width", 640), cam_desc.get("height", 480)
    fx, fy = cam_desc.get("fx", 525.0), cam_desc.get("fy", 525.0)
    cx, cy = cam_desc.get("cx", w / 2 - 0.5), cam_desc.get("cy", h / 2 - 0.5)
    if abs(fx - fy) > 1e-6 * fx:
        fail("camera: fx %g and fy %g differ; Cycles has one focal length" % (fx, fy))
    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    sc.collection.objects.link(cam)
    cam.data.sensor_fit = "HORIZONTAL"
    cam.data.sensor_width = w
    cam.data.lens = fx
    cam.data.shift_x = (w / 2 - (cx + 0.5)) / max(w, h)
    cam.data.shift_y = ((cy + 0.5) - h / 2) / max(w, h)
    cam.data.clip_start = 1e-3
    cam.data.clip_end = 1e4
    env_cam = None
    if desc.get("env_camera"):
        e = desc["env_camera"]
        env_cam = bpy.data.objects.new("env_camera", bpy.data.cameras.new("env_camera"))
        sc.collection.objects.link(env_cam)
        env_cam.data.type = "PANO"
        env_cam.data.cycles.panorama_type = "FISHEYE_EQUIDISTANT"
        env_cam.data.cycles.fisheye_fov = math.radians(e.get("fov_deg", 180.0))
        env_cam.data.sensor_fit = "HORIZONTAL"
        p = vec(e.get("position"), (0, 0, 0))
        env_cam.matrix_world = opencv_to_blender_camera(p, look_rotation(p, vec(e.get("look_at"), (0, 1, 0)),
                                                                         vec(e.get("up"), (0, 0, 1))))

    def show_virtual(on):
        for _, _, obs in virtual:
            for ob in obs:
                ob.hide_render = not on

    report_path = os.path.join(outdir, "renders.json")
    report = {"description": os.path.abspath(desc_path), "blender": bpy.app.version_string, "spp": spp,
              "seed": bpy.context.scene.cycles.seed,
              "frames": frames, "threads": opts["threads"], "frame_seconds": {}}
    if os.path.exists(report_path):
        with open(report_path) as f:
            old = json.load(f)
        if old.get("spp") != spp or old.get("seed") != report["seed"] or old.get("description") != report["description"]:
            fail("%s holds renders of %s at %s spp, seed %s; use another OUTDIR or remove it" %
                 (outdir, old.get("description"), old.get("spp"), old.get("seed")))
        report["frame_seconds"] = old.get("frame_seconds", {})
    for f in range(frames):
        names = ["C", "G", "depth", "normal", "mask"] + (["env"] if env_cam else [])
        if all(os.path.exists(os.path.join(outdir, "%06d_%s.exr" % (f, n))) for n in names):
            continue
        start = time.time()
        t = f / fps
        for v, root, _ in virtual:
            rate = Vector(v.get("angular_velocity_deg", (0, 0, 0)))
            spin = Quaternion(rate.normalized(), math.radians(rate.length * t)) if rate.length > 0 else Quaternion()
            m = (Matrix.Translation(vec(v.get("position"), (0, 0, 0)) + t * vec(v.get("velocity"), (0, 0, 0)))
                 @ (spin @ quat_xyzw(v.get("rotation"))).normalized().to_matrix().to_4x4()
                 @ Matrix.Scale(v.get("scale", 1.0), 4))
            root.matrix_world = B @ m @ B_INV
        p, rot = camera_pose_at(desc, t)
        cam.matrix_world = opencv_to_blender_camera(p, rot)
        sc.camera = cam
        sc.render.resolution_x, sc.render.resolution_y = w, h
        show_virtual(False)
        render_to({"C": "Image"}, comp, outdir, f, spp, 1.0)
        render_to({"depth": comp["depth"], "normal": comp["normal"]}, comp, outdir, f, 1, 0.01)
        show_virtual(True)
        render_to({"G": "Image"}, comp, outdir, f, spp, 1.0)
        render_to({"mask": "IndexOB"}, comp, outdir, f, 1, 0.01)
        if env_cam:
            show_virtual(False)
            sc.camera = env_cam
            size = desc["env_camera"].get("size", 256)
            sc.render.resolution_x = sc.render.resolution_y = size
            render_to({"env": "Image"}, comp, outdir, f, desc["env_camera"].get("spp", 16), 1.0)
        report["frame_seconds"][str(f)] = round(time.time() - start, 1)
        with open(report_path, "w") as fh:
            json.dump(report, fh, indent=1)
        print("render_description: frame %d done in %.1f s" % (f, time.time() - start), flush=True)


main()
