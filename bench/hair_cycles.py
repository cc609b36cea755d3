"""bench/hair_cycles.py — bench/hair's scene in Blender's Cycles.

  blender -b --factory-startup --python bench/hair_cycles.py -- CONFIG.json

CONFIG (written by bench/hair.py): the strands' Bezier control points in
pbrt's coordinates (y up; taken to Blender's z-up by (x, y, z) ->
(x, -z, y), a rotation), sigma_a, size, bounces, samples, threads, out.
The strands become a hair-curves object (geometry nodes: a mesh of
17-point polylines to curves, radius from a point attribute) under a
Principled Hair BSDF (absorption coefficient, roughness and radial
roughness 0.3, IOR 1.55, offset 2 degrees, no coat, no randomness).
Cycles: path tracing, no adaptive sampling, no denoising, no clamping,
caustics on, every bounce kind to `bounces`.
"""
import json
import math
import sys

import bpy
from mathutils import Vector

cfg = json.load(open(sys.argv[sys.argv.index("--") + 1]))


def B(p):
    return Vector((p[0], -p[2], p[1]))


scene = bpy.context.scene
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
scene.render.engine = 'CYCLES'
cy = scene.cycles
cy.device = 'CPU'
cy.samples = cfg["samples"]
cy.use_adaptive_sampling = False
cy.use_denoising = False
nb = cfg["bounces"]
cy.max_bounces = cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = nb
cy.transparent_max_bounces = 8
cy.caustics_reflective = cy.caustics_refractive = True
cy.sample_clamp_direct = cy.sample_clamp_indirect = 0
cy.blur_glossy = 0
scene.render.resolution_x = scene.render.resolution_y = cfg["size"]
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = 'OPEN_EXR'
scene.render.image_settings.color_depth = '32'
scene.view_settings.view_transform = 'Standard'
scene.render.threads_mode = 'FIXED'
scene.render.threads = cfg["threads"]
scene.cycles_curves.shape = 'THICK'

cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(cam)
cam.location = B((0, 0.3, 4))
cam.rotation_euler = (Vector((0, 0, 0)) - cam.location).to_track_quat('-Z', 'Y').to_euler()
cam.data.angle = math.radians(30)
scene.camera = cam

world = bpy.data.worlds.new("sky")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (0.3, 0.3, 0.35, 1)
scene.world = world
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", 'SUN'))
scene.collection.objects.link(sun)
sun.data.energy = 3.0
sun.data.angle = 0.0
sun.rotation_euler = (Vector((0, 0, 0)) - B((3, 4, 2))).to_track_quat('-Z', 'Y').to_euler()

bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, segments=128, ring_count=64)
ball = bpy.context.active_object
bpy.ops.object.shade_smooth()
grey = bpy.data.materials.new("grey")
grey.use_nodes = True
nt = grey.node_tree
nt.nodes.clear()
diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
diffuse.inputs["Color"].default_value = (0.4, 0.4, 0.4, 1)
nt.links.new(diffuse.outputs[0], nt.nodes.new("ShaderNodeOutputMaterial").inputs[0])
ball.data.materials.append(grey)

K = 17  # points a strand
verts, edges, radii = [], [], []
for i, cps in enumerate(cfg["strands"]):
    for k in range(K):
        t = k / (K - 1)
        w = ((1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t * t * (1 - t), t ** 3)
        verts.append(tuple(B([sum(w[m] * cps[m][j] for m in range(4)) for j in range(3)])))
        radii.append(0.5 * (0.008 + (0.004 - 0.008) * t))
        if k:
            edges.append((i * K + k - 1, i * K + k))
mesh = bpy.data.meshes.new("strands")
mesh.from_pydata(verts, edges, [])
rad = mesh.attributes.new("rad", 'FLOAT', 'POINT')
for i, r in enumerate(radii):
    rad.data[i].value = r
source = bpy.data.objects.new("strands", mesh)

hair = bpy.data.materials.new("hair")
hair.use_nodes = True
nt = hair.node_tree
nt.nodes.clear()
bsdf = nt.nodes.new("ShaderNodeBsdfHairPrincipled")
bsdf.parametrization = 'ABSORPTION'
bsdf.inputs["Absorption Coefficient"].default_value = tuple(cfg["sigma_a"])
bsdf.inputs["Roughness"].default_value = 0.3
bsdf.inputs["Radial Roughness"].default_value = 0.3
bsdf.inputs["Coat"].default_value = 0.0
bsdf.inputs["IOR"].default_value = 1.55
bsdf.inputs["Offset"].default_value = math.radians(2.0)
bsdf.inputs["Random Roughness"].default_value = 0.0
bsdf.inputs["Random Color"].default_value = 0.0
nt.links.new(bsdf.outputs[0], nt.nodes.new("ShaderNodeOutputMaterial").inputs[0])

curves = bpy.data.objects.new("hair", bpy.data.hair_curves.new("hair"))
scene.collection.objects.link(curves)
ng = bpy.data.node_groups.new("strands", 'GeometryNodeTree')
ng.inputs.new('NodeSocketGeometry', "Geometry")
ng.outputs.new('NodeSocketGeometry', "Geometry")
info = ng.nodes.new("GeometryNodeObjectInfo")
info.inputs["Object"].default_value = source
to_curves = ng.nodes.new("GeometryNodeMeshToCurve")
radius = ng.nodes.new("GeometryNodeSetCurveRadius")
named = ng.nodes.new("GeometryNodeInputNamedAttribute")
named.data_type = 'FLOAT'
named.inputs[0].default_value = "rad"
material = ng.nodes.new("GeometryNodeSetMaterial")
material.inputs["Material"].default_value = hair
out = ng.nodes.new("NodeGroupOutput")
ng.links.new(info.outputs["Geometry"], to_curves.inputs[0])
ng.links.new(to_curves.outputs[0], radius.inputs[0])
ng.links.new([o for o in named.outputs if o.enabled][0], radius.inputs["Radius"])
ng.links.new(radius.outputs[0], material.inputs[0])
ng.links.new(material.outputs[0], out.inputs[0])
curves.modifiers.new("strands", 'NODES').node_group = ng

scene.render.filepath = cfg["out"]
bpy.ops.render.render(write_still=True)
