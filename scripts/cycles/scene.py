# Renders an OBJ scene with Blender's Cycles as tracer renders it (scripts/benchmarks-cycles.sh):
# the same camera, the MTL's materials rebuilt to tracer's model (shade/material_bsdf.hpp) as
# Cycles nodes, one-sided emitters, a uniform sky, a 1-pixel box filter, no denoiser, no clamping,
# no filter glossy. Linear radiance to an OpenEXR file; prints the render's own time.
#   blender -b --factory-startup -noaudio --python scene.py -- --obj F --out F.exr [options]
import argparse
import math
import os
import sys
import time

import bmesh
import bpy
from mathutils import Vector

p = argparse.ArgumentParser()
p.add_argument('--obj', required=True)
p.add_argument('--out', required=True)
p.add_argument('--size', type=int, default=512)
p.add_argument('--spp', type=int, default=16, help='samples per pixel (with --threshold: at most)')
p.add_argument('--threshold', type=float, default=0.0, help="adaptive sampling's noise threshold; 0: off")
p.add_argument('--seed', type=int, default=0)
p.add_argument('--threads', type=int, default=2)
p.add_argument('--max-depth', type=int, default=8)
p.add_argument('--eye', required=True)
p.add_argument('--look', required=True)
p.add_argument('--up', default='0,1,0')
p.add_argument('--fov', type=float, default=60.0)
p.add_argument('--env', default='0,0,0', help="the sky's radiance")
args = p.parse_args(sys.argv[sys.argv.index('--') + 1:])

vec = lambda s: Vector([float(x) for x in s.split(',')])
# OBJ's y-up (x, y, z) is Blender's (x, -z, y): the importer's forward -Z, up Y.
blender_axes = lambda v: Vector((v.x, -v.z, v.y))

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.obj_import(filepath=args.obj, forward_axis='NEGATIVE_Z', up_axis='Y')

# A face that repeats another's corners (the Cornell Original's tall block lists one twice) is the
# same surface to tracer; Cycles would shade the pair as two surfaces a hair apart, shadowing each
# other. Keep one.
for obj in [o for o in bpy.context.scene.objects if o.type == 'MESH']:
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    seen, twins = set(), []
    for f in bm.faces:
        key = tuple(sorted(tuple(round(c, 6) for c in v.co) for v in f.verts))
        (twins.append(f) if key in seen else seen.add(key))
    if twins:
        bmesh.ops.delete(bm, geom=twins, context='FACES_ONLY')
        print(f'cycles-scene: {obj.name}: {len(twins)} repeated faces removed')
    bm.to_mesh(obj.data)
    bm.free()

# The MTL, read as tracer reads it: what shade/material_bsdf.hpp builds from these keys.
folder = os.path.dirname(os.path.abspath(args.obj))
mtllib = next((l.split(None, 1)[1].strip() for l in open(args.obj, errors='replace') if l.startswith('mtllib')), None)
mtl, cur = {}, None
for line in open(os.path.join(folder, mtllib), errors='replace') if mtllib else []:
    t = line.split('#')[0].split()
    if not t:
        continue
    if t[0] == 'newmtl':
        cur = mtl.setdefault(t[1], {})
    elif cur is None:
        continue
    elif t[0] in ('Kd', 'Ks', 'Ke', 'Tf'):
        cur[t[0]] = [float(x) for x in t[1:4]] * (3 if len(t) == 2 else 1)
    elif t[0] in ('Ns', 'Ni', 'illum'):
        cur[t[0]] = float(t[1])
    elif t[0] in ('map_Kd', 'map_bump', 'bump'):
        opts, i = {}, 1
        while i < len(t) - 1 and t[i].startswith('-'):
            opts[t[i]] = t[i + 1]
            i += 2
        cur['bump' if t[0] != 'map_Kd' else 'map_Kd'] = (os.path.join(folder, t[-1]), float(opts.get('-bm', 1)))


def image(path, data):
    if not os.path.exists(path):  # exporters' names often differ in case from the files (Sponza's), as tracer finds them
        d, name = os.path.split(path)
        path = os.path.join(d, next((f for f in os.listdir(d) if f.lower() == name.lower()), name))
    img = bpy.data.images.load(path, check_existing=True)
    if data:
        img.colorspace_settings.name = 'Non-Color'
    return img


def build(m, d):
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    node = lambda kind: nt.nodes.new(kind)
    link = lambda a, b: nt.links.new(a, b)
    out = node('ShaderNodeOutputMaterial')
    illum = int(d.get('illum', 2))
    ks = d.get('Ks', [0.0] * 3)
    normal = None
    if 'bump' in d:  # the surface displaced by -bm times the height, the mean of the texel's bytes
        tex = node('ShaderNodeTexImage')
        tex.image = image(d['bump'][0], True)
        sep = node('ShaderNodeSeparateColor')
        link(tex.outputs['Color'], sep.inputs[0])
        add1, add2, third = node('ShaderNodeMath'), node('ShaderNodeMath'), node('ShaderNodeMath')
        add1.operation = add2.operation = 'ADD'
        third.operation = 'MULTIPLY'
        third.inputs[1].default_value = 1.0 / 3.0
        link(sep.outputs[0], add1.inputs[0]); link(sep.outputs[1], add1.inputs[1])
        link(add1.outputs[0], add2.inputs[0]); link(sep.outputs[2], add2.inputs[1])
        link(add2.outputs[0], third.inputs[0])
        bump = node('ShaderNodeBump')
        bump.inputs['Strength'].default_value = 1.0
        bump.inputs['Distance'].default_value = d['bump'][1]
        link(third.outputs[0], bump.inputs['Height'])
        normal = bump.outputs['Normal']
    if illum in (3, 5):  # a mirror of reflectance Ks
        surf = node('ShaderNodeBsdfGlossy')
        surf.distribution = 'SHARP'
        surf.inputs['Color'].default_value = (*ks, 1)
    elif illum in (4, 6, 7, 9):  # a smooth dielectric: reflection by Fresnel, transmission filtered by Tf
        ior = d.get('Ni', 1.5)
        refl, refr, mix, fres = node('ShaderNodeBsdfGlossy'), node('ShaderNodeBsdfRefraction'), \
            node('ShaderNodeMixShader'), node('ShaderNodeFresnel')
        refl.distribution = refr.distribution = 'SHARP'
        refl.inputs['Color'].default_value = (1, 1, 1, 1)
        refr.inputs['Color'].default_value = (*d.get('Tf', [1.0] * 3), 1)
        refr.inputs['IOR'].default_value = fres.inputs['IOR'].default_value = ior
        link(fres.outputs[0], mix.inputs[0])
        link(refr.outputs[0], mix.inputs[1])
        link(refl.outputs[0], mix.inputs[2])
        surf = mix
    else:  # Lambert from Kd (or map_Kd), plus a GGX lobe of Ks with width from Ns; scaled to sum <= 1
        kd = d.get('Kd', [0.8] * 3)
        ks = ks if illum >= 2 else [0.0] * 3
        scale = 1.0 / max(1.0, max(a + b for a, b in zip(kd, ks)))
        dif = node('ShaderNodeBsdfDiffuse')
        if 'map_Kd' in d:
            tex = node('ShaderNodeTexImage')
            tex.image = image(d['map_Kd'][0], False)
            link(tex.outputs['Color'], dif.inputs['Color'])
        else:
            dif.inputs['Color'].default_value = (*[c * scale for c in kd], 1)
        surf = dif
        if max(ks) > 0:
            alpha = min(max(math.sqrt(2.0 / (max(d.get('Ns', 0.0), 0.0) + 2.0)), 0.01), 1.0)
            glo, add = node('ShaderNodeBsdfGlossy'), node('ShaderNodeAddShader')
            glo.distribution = 'GGX'
            glo.inputs['Roughness'].default_value = math.sqrt(alpha)  # Cycles squares it
            glo.inputs['Color'].default_value = (*[c * scale for c in ks], 1)
            if normal:
                link(normal, glo.inputs['Normal'])
            link(dif.outputs[0], add.inputs[0])
            link(glo.outputs[0], add.inputs[1])
            surf = add
        if normal:
            link(normal, dif.inputs['Normal'])
    ke = d.get('Ke', [0.0] * 3)
    if max(ke) > 0:  # emission from the front face only, as tracer's emitters
        em, geo, front, add = node('ShaderNodeEmission'), node('ShaderNodeNewGeometry'), node('ShaderNodeMath'), \
            node('ShaderNodeAddShader')
        em.inputs['Color'].default_value = (*ke, 1)
        front.operation = 'SUBTRACT'
        front.inputs[0].default_value = 1.0
        link(geo.outputs['Backfacing'], front.inputs[1])
        link(front.outputs[0], em.inputs['Strength'])
        link(surf.outputs[0], add.inputs[0])
        link(em.outputs[0], add.inputs[1])
        surf = add
    link(surf.outputs[0], out.inputs['Surface'])


for m in bpy.data.materials:
    build(m, mtl.get(m.name, {}))

scene = bpy.context.scene
cam = bpy.data.cameras.new('camera')
cam_obj = bpy.data.objects.new('camera', cam)
scene.collection.objects.link(cam_obj)
eye, look = blender_axes(vec(args.eye)), blender_axes(vec(args.look))
cam_obj.location = eye
up = blender_axes(vec(args.up))
forward = (look - eye).normalized()
right = forward.cross(up).normalized()
cam_obj.rotation_euler = (forward.to_track_quat('-Z', 'Y').to_matrix().to_4x4()).to_euler()
# to_track_quat keeps Blender's Z up; tracer's up (the OBJ's +y) is that Z, so no roll is needed.
cam.sensor_fit = 'VERTICAL'
cam.angle_y = math.radians(args.fov)
scene.camera = cam_obj

scene.world = bpy.data.worlds.new('sky')
scene.world.use_nodes = True
scene.world.node_tree.nodes['Background'].inputs['Color'].default_value = (*vec(args.env), 1)
scene.world.node_tree.nodes['Background'].inputs['Strength'].default_value = 1.0

scene.render.engine = 'CYCLES'
c = scene.cycles
c.device = 'CPU'
c.samples = args.spp
c.seed = args.seed
c.use_adaptive_sampling = args.threshold > 0
if args.threshold > 0:
    c.adaptive_threshold = args.threshold
c.use_denoising = False
c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = args.max_depth
c.transparent_max_bounces = args.max_depth
c.caustics_reflective = c.caustics_refractive = True
c.blur_glossy = 0.0
c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
c.pixel_filter_type = 'BOX'
c.filter_width = 1.0
scene.render.threads_mode = 'FIXED'
scene.render.threads = args.threads
scene.render.resolution_x = scene.render.resolution_y = args.size
scene.render.resolution_percentage = 100
scene.view_settings.view_transform = 'Standard'
scene.render.image_settings.file_format = 'OPEN_EXR'
scene.render.image_settings.color_depth = '32'
scene.render.filepath = args.out
start = time.time()
bpy.ops.render.render(write_still=True)
seconds = time.time() - start
print(f'cycles-scene: render {seconds:.3f} s, {args.size * args.size * args.spp / seconds / 1e6:.3f} Msamples/s at most')
