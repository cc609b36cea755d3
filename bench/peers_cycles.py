# bench/peers_cycles.py — cornell-teapots (../shared/data/cornell-teapots.md)
# built in Blender and rendered with Cycles at a list of sample counts, for
# bench/peers. Run by bench/peers.py as
#
#   blender -b --factory-startup --python bench/peers_cycles.py -- \
#       --data DIR --size N --bounces B --threads T --out DIR --samples 16,64,...
#
# Matched light transport (docs/performance.md, "Against Cycles"): B diffuse
# bounces, 4 glossy, no transmission; caustics off, no clamping, no
# denoising, no adaptive sampling, a box pixel filter of one pixel, a black
# world. Writes OUT/cycles-SPP.exr (linear RGBA float) per count and
# OUT/cycles.json with the CPU seconds (process time, every thread) and
# wall seconds of each render call.
import json
import math
import os
import sys
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
opt = {"data": "../shared/data", "size": "256", "bounces": "1", "threads": "2",
       "out": "bench-out/peers", "samples": "16,64"}
for i in range(0, len(argv) - 1, 2):
    opt[argv[i].lstrip("-")] = argv[i + 1]
size, bounces, threads = int(opt["size"]), int(opt["bounces"]), int(opt["threads"])
counts = [int(s) for s in opt["samples"].split(",") if s]
os.makedirs(opt["out"], exist_ok=True)

# An empty scene.
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def material(name, kind, colour):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    if kind == "diffuse":
        b = nodes.new("ShaderNodeBsdfDiffuse")
        b.inputs["Color"].default_value = (*colour, 1.0)
        b.inputs["Roughness"].default_value = 0.0
        links.new(b.outputs[0], out.inputs["Surface"])
    elif kind == "mirror":  # a perfect mirror, no Fresnel term (Cycles' glossy has none)
        b = nodes.new("ShaderNodeBsdfGlossy")
        b.distribution = "SHARP"
        b.inputs["Color"].default_value = (*colour, 1.0)
        links.new(b.outputs[0], out.inputs["Surface"])
    else:  # a one-sided emitter: radiance colour on the front, black behind
        e = nodes.new("ShaderNodeEmission")
        e.inputs["Color"].default_value = (*colour, 1.0)
        e.inputs["Strength"].default_value = 1.0
        black = nodes.new("ShaderNodeEmission")
        black.inputs["Strength"].default_value = 0.0
        geo = nodes.new("ShaderNodeNewGeometry")
        mix = nodes.new("ShaderNodeMixShader")
        links.new(geo.outputs["Backfacing"], mix.inputs[0])
        links.new(e.outputs[0], mix.inputs[1])
        links.new(black.outputs[0], mix.inputs[2])
        links.new(mix.outputs[0], out.inputs["Surface"])
    return m


def add_mesh(name, verts, faces, mat, normals=None):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.update()
    if normals is not None:
        for p in me.polygons:
            p.use_smooth = True
        me.use_auto_smooth = True
        me.normals_split_custom_set_from_vertices(normals)
    me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    scene.collection.objects.link(ob)
    return ob


white = material("white", "diffuse", (0.725, 0.71, 0.68))
red = material("red", "diffuse", (0.63, 0.065, 0.05))
green = material("green", "diffuse", (0.14, 0.45, 0.091))
grey = material("matte", "diffuse", (0.7, 0.7, 0.7))
chrome = material("chrome", "mirror", (0.9, 0.9, 0.9))
emitter = material("light", "emission", (17.0, 12.0, 4.0))

quads = [
    ("floor", white, [(552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2)]),
    ("ceiling", white, [(556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2), (0, 548.8, 0)]),
    ("back", white, [(549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2)]),
    ("green", green, [(0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2)]),
    ("red", red, [(552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0)]),
    ("light", emitter, [(343, 548.7, 227), (343, 548.7, 332), (213, 548.7, 332), (213, 548.7, 227)]),
]
for name, mat, v in quads:
    add_mesh(name, v, [(0, 1, 2, 3)], mat)


def read_bpt(path):
    rows = [l.split() for l in open(path) if l.strip() and not l.startswith("#")]
    n = int(rows[0][0])
    patches = [[int(i) - 1 for i in r] for r in rows[1:1 + n]]
    m = int(rows[1 + n][0])
    points = [tuple(float(x) for x in r) for r in rows[2 + n:2 + n + m]]
    return patches, points


def bernstein(t):
    s = 1.0 - t
    return (s * s * s, 3 * t * s * s, 3 * t * t * s, t * t * t)


def dbernstein(t):
    s = 1.0 - t
    return (-3 * s * s, 3 * s * s - 6 * t * s, 6 * t * s - 3 * t * t, 3 * t * t)


def teapot(name, mat, theta, tx, tz, patches, points, n=24):
    """world = T(tx, 0, tz) Ry(theta) S(45) (x, z, -y), each patch n x n
    quads with its exact normals (the degenerate rows' taken a step in)."""
    c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))

    def world(p):
        x, y, z = 45 * p[0], 45 * p[2], -45 * p[1]
        return (x * c + z * s + tx, y, -x * s + z * c + tz)

    verts, faces, normals = [], [], []
    for patch in patches:
        cp = [world(points[i]) for i in patch]
        base = len(verts)
        for j in range(n + 1):
            for i in range(n + 1):
                u, v = i / n, j / n
                bu, bv = bernstein(u), bernstein(v)
                p = [0.0, 0.0, 0.0]
                for a in range(4):
                    for b in range(4):
                        w = bv[a] * bu[b]
                        q = cp[4 * a + b]
                        p = [p[k] + w * q[k] for k in range(3)]
                verts.append(tuple(p))
                nrm = None
                for eps in (0.0, 1e-3, -1e-3):
                    uu = min(max(u + eps, 0.0), 1.0)
                    vv = min(max(v + eps, 0.0), 1.0)
                    bu2, bv2 = bernstein(uu), bernstein(vv)
                    du, dv = dbernstein(uu), dbernstein(vv)
                    pu, pv = [0.0] * 3, [0.0] * 3
                    for a in range(4):
                        for b in range(4):
                            q = cp[4 * a + b]
                            for k in range(3):
                                pu[k] += bv2[a] * du[b] * q[k]
                                pv[k] += dv[a] * bu2[b] * q[k]
                    cr = (pu[1] * pv[2] - pu[2] * pv[1], pu[2] * pv[0] - pu[0] * pv[2],
                          pu[0] * pv[1] - pu[1] * pv[0])
                    ln = math.sqrt(sum(x * x for x in cr))
                    if ln > 1e-9:
                        nrm = tuple(x / ln for x in cr)
                        break
                normals.append(nrm or (0.0, 1.0, 0.0))
        for j in range(n):
            for i in range(n):
                a = base + j * (n + 1) + i
                faces.append((a, a + 1, a + n + 2, a + n + 1))
    add_mesh(name, verts, faces, mat, normals)


patches, points = read_bpt(os.path.join(opt["data"], "teapot.bpt"))
teapot("chrome-teapot", chrome, 35.0, 395.0, 370.0, patches, points)
teapot("matte-teapot", grey, 150.0, 160.0, 195.0, patches, points)

# The camera at (278, 273, -800) looking along +z, up +y: its local -Z is
# the view, +Y up, so +X (the image's right) is world -x.
cam_data = bpy.data.cameras.new("camera")
# A square sensor: the field of view is the same across and up (Blender's
# angle setter works on the sensor's width whatever the fit).
cam_data.sensor_fit = "AUTO"
cam_data.sensor_width = cam_data.sensor_height = 36.0
cam_data.angle = math.radians(39.3077)
cam_data.clip_start = 1.0
cam_data.clip_end = 10000.0
cam = bpy.data.objects.new("camera", cam_data)
scene.collection.objects.link(cam)
from mathutils import Matrix  # noqa: E402
cam.matrix_world = Matrix(((-1, 0, 0, 278), (0, 1, 0, 273), (0, 0, -1, -800), (0, 0, 0, 1)))
scene.camera = cam

world = bpy.data.worlds.new("black")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
scene.world = world

r = scene.render
r.engine = "CYCLES"
r.resolution_x = r.resolution_y = size
r.resolution_percentage = 100
r.threads_mode = "FIXED"
r.threads = threads
r.image_settings.file_format = "OPEN_EXR"
r.image_settings.color_depth = "32"
r.image_settings.color_mode = "RGBA"
scene.view_settings.view_transform = "Standard"
cy = scene.cycles
cy.device = "CPU"
cy.use_adaptive_sampling = False
cy.use_denoising = False
cy.max_bounces = bounces + 4
cy.diffuse_bounces = bounces
cy.glossy_bounces = 4
cy.transmission_bounces = 0
cy.volume_bounces = 0
cy.transparent_max_bounces = 0
cy.caustics_reflective = False
cy.caustics_refractive = False
cy.blur_glossy = 0.0
cy.sample_clamp_direct = 0.0
cy.sample_clamp_indirect = 0.0
cy.pixel_filter_type = "BOX"
cy.filter_width = 1.0
cy.seed = 0
cy.use_animated_seed = False

record = []
for spp in counts:
    cy.samples = spp
    r.filepath = os.path.abspath(os.path.join(opt["out"], "cycles-%d.exr" % spp))
    c0, w0 = time.process_time(), time.perf_counter()
    bpy.ops.render.render(write_still=True)
    record.append({"spp": spp, "cpu_s": time.process_time() - c0,
                   "wall_s": time.perf_counter() - w0, "image": r.filepath})
    print("peers_cycles: %d samples, %.2f s cpu" % (spp, record[-1]["cpu_s"]), flush=True)
with open(os.path.join(opt["out"], "cycles.json"), "w") as f:
    json.dump(record, f, indent=1)
