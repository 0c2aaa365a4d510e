"""The head's diagnostics (docs/subsurface.md, "A head"): one scene against Cycles, 32x32, two
seeds of each renderer; prints Lantern / Cycles means. Usage, from the repository root:
  python bench/sss_head_diagnostics.py NAME SPP [OPTIONS...]
NAME: suz, suz_noeyes, suz_sub, suz_flipcheck, sphere, sphere_hole, sphere_hole_back,
sphere_inner, sphere_eye, sphere_flip; OPTIONS: nosss, flat, diffuse, sun, nocorr (Cycles'
Bump Map Correction off), nogeo (Shadow Terminator Geometry Offset 0 in both), lan0 (0 in
Lantern's export alone), sNN (Radius x Scale NN cm red, as s25), sub2 (subdivided twice),
k=N (N seeds a side instead of 2).
Images go to /tmp/ssshead."""
import os, sys, time, numpy as np
R = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, R + '/tests/cycles'); sys.path.insert(0, R + '/tools'); sys.path.insert(0, R + '/python')
os.makedirs('/tmp/ssshead', exist_ok=True)
import bpy, bmesh
import test_subsurface as t, render_compare as rc
name = sys.argv[1]; spp = int(sys.argv[2]) if len(sys.argv) > 2 else 128
def skinmat():
    return t._material("skin", (0.8, 0.55, 0.45), roughness=0.5, sss=1.0, radius=(1.0, 0.35, 0.2), scale=0.08, method="RANDOM_WALK_SKIN")
def base(obj_fn):
    scene = t._reset()
    obj_fn()
    obj = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(skinmat())
    t._light(scene, "POINT", (1.0, -2.0, 1.5), 300.0, shadow_soft_size=0.2)
    t._camera(scene, (0, -3.5, 0.2), (88, 0, 0), lens=45.0)
    return obj
def islands(obj):
    bm = bmesh.new(); bm.from_mesh(obj.data); bm.faces.ensure_lookup_table()
    seen=set(); comps=[]
    for f in bm.faces:
        if f.index in seen: continue
        stack=[f]; comp=[]; seen.add(f.index)
        while stack:
            g=stack.pop(); comp.append(g.index)
            for e in g.edges:
                for h in e.link_faces:
                    if h.index not in seen: seen.add(h.index); stack.append(h)
        comps.append(comp)
    return bm, comps
def suz(): bpy.ops.mesh.primitive_monkey_add(rotation=(0,0,0))
if name == 'suz': base(suz)
elif name == 'suz_noeyes':
    o = base(suz); bm, comps = islands(o); comps.sort(key=len)
    print('islands', [len(c) for c in comps])
    kill = set(i for c in comps[:-1] for i in c)
    bmesh.ops.delete(bm, geom=[f for f in bm.faces if f.index in kill], context='FACES')
    bm.to_mesh(o.data)
elif name == 'sphere': base(lambda: bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, segments=32, ring_count=16))
elif name == 'sphere_hole':
    o = base(lambda: bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, segments=32, ring_count=16))
    bm = bmesh.new(); bm.from_mesh(o.data)
    bmesh.ops.delete(bm, geom=[f for f in bm.faces if f.calc_center_median().y < -0.55], context='FACES')
    bm.to_mesh(o.data)
elif name == 'sphere_hole_back':
    o = base(lambda: bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, segments=32, ring_count=16))
    bm = bmesh.new(); bm.from_mesh(o.data)
    bmesh.ops.delete(bm, geom=[f for f in bm.faces if f.calc_center_median().y > 0.45], context='FACES')
    bm.to_mesh(o.data)
elif name == 'sphere_inner':
    def f():
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, segments=32, ring_count=16)
        bm = bmesh.new(); bm.from_mesh(bpy.context.active_object.data)
        r = bmesh.ops.create_uvsphere(bm, u_segments=16, v_segments=8, radius=0.3)
        bmesh.ops.translate(bm, vec=(0.0, -0.3, 0.0), verts=r['verts'])
        bm.to_mesh(bpy.context.active_object.data)
    base(f)
elif name == 'sphere_eye':
    def f():
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, segments=32, ring_count=16)
        bm = bmesh.new(); bm.from_mesh(bpy.context.active_object.data)
        r = bmesh.ops.create_uvsphere(bm, u_segments=16, v_segments=8, radius=0.25)
        bmesh.ops.translate(bm, vec=(0.25, -0.62, 0.15), verts=r['verts'])
        bm.to_mesh(bpy.context.active_object.data)
    base(f)
elif name == 'sphere_flip':  # the same sphere, normals inward
    o = base(lambda: bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, segments=32, ring_count=16))
    bm = bmesh.new(); bm.from_mesh(o.data); bmesh.ops.reverse_faces(bm, faces=bm.faces[:]); bm.to_mesh(o.data)
elif name == 'suz_sub':
    o = base(suz); m = o.modifiers.new('s','SUBSURF'); m.levels = 2; m.render_levels = 2
elif name == 'suz_flipcheck':
    o = base(suz); o.data.update(); import mathutils
    bm = bmesh.new(); bm.from_mesh(o.data); bm.faces.ensure_lookup_table()
    c = sum((v.co for v in bm.verts), mathutils.Vector())/len(bm.verts)
    print('outward-ish', sum(1 for f in bm.faces if f.normal.dot(f.calc_center_median()-c) > 0), len(bm.faces))
    bmesh.ops.recalc_face_normals(bm, faces=bm.faces[:])
    print('after recalc outward', sum(1 for f in bm.faces if f.normal.dot(f.calc_center_median()-c) > 0))
    bm.to_mesh(o.data)
if 'nosss' in sys.argv[3:]:
    bpy.data.materials['skin'].node_tree.nodes['Principled BSDF'].inputs['Subsurface Weight'].default_value = 0.0
if 'flat' in sys.argv[3:]: bpy.ops.object.shade_flat()
for a in sys.argv[3:]:  # sNN: Radius x Scale NN cm red
    if a[:1] == 's' and a[1:].isdigit():
        bpy.data.materials['skin'].node_tree.nodes['Principled BSDF'].inputs['Subsurface Scale'].default_value = int(a[1:]) / 100
if 'sub2' in sys.argv[3:]:
    m = bpy.context.active_object.modifiers.new('s','SUBSURF'); m.levels = m.render_levels = 2
if 'nocorr' in sys.argv[3:]:
    for m in bpy.data.materials: m.cycles.use_bump_map_correction = False
if 'diffuse' in sys.argv[3:]:
    p = bpy.data.materials['skin'].node_tree.nodes['Principled BSDF']
    p.inputs['Roughness'].default_value = 1.0; p.inputs['Specular IOR Level'].default_value = 0.0
if 'sun' in sys.argv[3:]:
    for o in list(bpy.data.objects):
        if o.type == 'LIGHT': bpy.data.objects.remove(o)
    t._light(bpy.context.scene, "SUN", (1.0, -2.0, 1.5), 3.0, rotation=(50, 0, 30))
if 'nogeo' in sys.argv[3:]:
    for o in bpy.data.objects:
        if o.type == 'MESH': o.shadow_terminator_geometry_offset = 0.0  # (o.cycles': unused)
if 'geoinfo' in sys.argv[3:]:
    for o in bpy.data.objects:
        if o.type == 'MESH': print('geo offset', o.shadow_terminator_geometry_offset, o.shadow_terminator_shading_offset)
if 'lan0' in sys.argv[3:]:  # Lantern alone without the terminator offset (Cycles keeps it)
    _render = rc.render_lantern
    def lan0(**kw):
        for o in bpy.data.objects:
            if o.type == 'MESH': o.shadow_terminator_geometry_offset = 0.0
        return _render(**kw)
    rc.render_lantern = lan0
t0=time.time()
K = next((int(a[2:]) for a in sys.argv[3:] if a.startswith('k=')), 2)  # seeds a side
cyc = np.mean([rc.render_cycles(seed=900+k, spp=spp)[0] for k in range(K)], axis=0)
t1=time.time()
lan = np.mean([rc.render_lantern(seed=1+k, spp=spp, threads=1)[0] for k in range(K)], axis=0)
t2=time.time()
tag = '_'.join([name]+sys.argv[3:]).replace('=', '')
np.save(f'/tmp/ssshead/{tag}_cyc.npy', cyc); np.save(f'/tmp/ssshead/{tag}_lan.npy', lan)
print(tag, 'ratio %.4f' % (lan.mean()/cyc.mean()), 'ch', [round(float(lan[...,k].mean()/cyc[...,k].mean()),4) for k in range(3)], 'times %.0f %.0f' % (t1-t0, t2-t1), flush=True)
