"""Node-graph scenes (issue 16): a lit floor and three spheres whose materials are driven by
shader-node graphs, one scene per node family. 48 x 48 pixels, view transform Standard, black
world, one 200 W 1 m area light; tests/cycles/test_node_scenes.py renders them by Cycles and
Lantern.

- `nodes_procedural`: textures on Generated / Object / UV coordinates through Mapping:
  Checker x Noise (fBm, distortion) on the floor, Wave (rings) and Magic through a ColorRamp,
  Gradient and a 4D Noise through Hue/Saturation, White Noise on floored coordinates.
- `nodes_utility`: Math, Vector Math, Map Range, Clamp, Mix (colour blend modes), RGB Curves,
  Separate/Combine HSV, Bright/Contrast, Gamma, Invert, a node group and a reroute; a
  Layer Weight factor mixing Diffuse and Glossy; a noise-driven emission quad (lit by it).
- `nodes_vector`: Bump (strength, distance, invert, two chained), the Displacement output as
  bump, Mapping, Vector Math.
- `nodes_input`: Geometry, Texture Coordinate, Object Info, Color Attribute; the light through
  its node tree (Blackbody).
- `nodes_world`: a procedural world (Gradient, Noise, ColorRamp, Mix) lighting the scene.

    .venv/bin/python blend_scenes/nodes.py nodes_procedural out.blend"""

import math
import sys

import bpy


def _reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.resolution_x = sc.render.resolution_y = 48
    sc.render.resolution_percentage = 100
    sc.view_settings.view_transform = "Standard"
    world = bpy.data.worlds.new("World")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    sc.world = world
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location, cam.rotation_euler = (0.0, -5.0, 2.2), (math.radians(70), 0.0, 0.0)
    cam.data.lens = 40.0
    sc.collection.objects.link(cam)
    sc.camera = cam
    light = bpy.data.lights.new("Area", "AREA")
    light.energy, light.size = 200.0, 1.0
    lo = bpy.data.objects.new("Area", light)
    lo.location, lo.rotation_euler = (1.5, -1.5, 3.5), (math.radians(30), math.radians(20), 0)
    sc.collection.objects.link(lo)
    return sc


def _material(name, shader="ShaderNodeBsdfDiffuse"):
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(n)
    s = nt.nodes.new(shader)
    nt.links.new(s.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return mat, nt, s


def _floor(mat):
    bpy.ops.mesh.primitive_plane_add(size=6.0)
    bpy.context.object.data.materials.append(mat)


def _sphere(mat, x, r=0.7):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=r,
                                         location=(x, 0.3, r))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(mat)


def _node(nt, idname, props=None, **inputs):
    n = nt.nodes.new(idname)
    for k, v in (props or {}).items():
        setattr(n, k, v)
    for k, v in inputs.items():
        next(s for s in n.inputs if s.identifier == k).default_value = v
    return n


def _ident(sockets, identifier):
    return next(s for s in sockets if s.identifier == identifier)


def nodes_procedural():
    _reset()
    mat, nt, d = _material("Floor")
    coord = nt.nodes.new("ShaderNodeTexCoord")
    mapping = _node(nt, "ShaderNodeMapping", Rotation=(0, 0, 0.4), Scale=(2, 2, 2))
    nt.links.new(coord.outputs["Object"], mapping.inputs["Vector"])
    chk = _node(nt, "ShaderNodeTexChecker", Scale=1.0, Color1=(0.8, 0.8, 0.75, 1),
                Color2=(0.2, 0.25, 0.3, 1))
    nt.links.new(mapping.outputs[0], chk.inputs["Vector"])
    noise = _node(nt, "ShaderNodeTexNoise", Scale=3.0, Detail=4.0, Distortion=0.6)
    mix = _node(nt, "ShaderNodeMix", {"data_type": "RGBA", "blend_type": "MULTIPLY"},
                Factor_Float=0.6)
    nt.links.new(chk.outputs["Color"], _ident(mix.inputs, "A_Color"))
    nt.links.new(noise.outputs["Color"], _ident(mix.inputs, "B_Color"))
    nt.links.new(_ident(mix.outputs, "Result_Color"), d.inputs["Color"])
    _floor(mat)

    mat, nt, d = _material("Rings")
    wave = _node(nt, "ShaderNodeTexWave", {"wave_type": "RINGS"}, Scale=1.5, Distortion=3.0)
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.7, 0.2, 0.1, 1)
    ramp.color_ramp.elements[1].color = (0.9, 0.8, 0.3, 1)
    nt.links.new(wave.outputs["Fac"], ramp.inputs[0])
    nt.links.new(ramp.outputs["Color"], d.inputs["Color"])
    _sphere(mat, -1.6)

    mat, nt, d = _material("Magic")
    magic = _node(nt, "ShaderNodeTexMagic", Scale=3.0, Distortion=1.2)
    grad = _node(nt, "ShaderNodeTexGradient", {"gradient_type": "SPHERICAL"})
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["Object"], grad.inputs["Vector"])
    m2 = _node(nt, "ShaderNodeMix", {"data_type": "RGBA", "blend_type": "SCREEN"},
               Factor_Float=0.5)
    nt.links.new(magic.outputs["Color"], _ident(m2.inputs, "A_Color"))
    nt.links.new(grad.outputs["Color"], _ident(m2.inputs, "B_Color"))
    nt.links.new(_ident(m2.outputs, "Result_Color"), d.inputs["Color"])
    _sphere(mat, 0.0)

    mat, nt, d = _material("Noise4D")
    n4 = _node(nt, "ShaderNodeTexNoise", {"noise_dimensions": "4D"}, Scale=2.0, W=1.3,
               Detail=2.0)
    hsv = _node(nt, "ShaderNodeHueSaturation", Hue=0.2, Saturation=1.3)
    nt.links.new(n4.outputs["Color"], hsv.inputs["Color"])
    white = _node(nt, "ShaderNodeTexWhiteNoise")
    fl = _node(nt, "ShaderNodeVectorMath", {"operation": "SNAP"}, Vector_001=(0.3, 0.3, 0.3))
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["Generated"], fl.inputs[0])
    nt.links.new(fl.outputs[0], white.inputs["Vector"])
    m3 = _node(nt, "ShaderNodeMix", {"data_type": "RGBA"}, Factor_Float=0.25)
    nt.links.new(hsv.outputs["Color"], _ident(m3.inputs, "A_Color"))
    nt.links.new(white.outputs["Color"], _ident(m3.inputs, "B_Color"))
    nt.links.new(_ident(m3.outputs, "Result_Color"), d.inputs["Color"])
    _sphere(mat, 1.6)
    return bpy.context.scene


def _group():
    """A node group: (value) -> smoothstep map range to [0.15, 0.85]."""
    g = bpy.data.node_groups.new("Remap", "ShaderNodeTree")
    g.interface.new_socket("Value", in_out="INPUT", socket_type="NodeSocketFloat")
    g.interface.new_socket("Result", in_out="OUTPUT", socket_type="NodeSocketFloat")
    gin, gout = g.nodes.new("NodeGroupInput"), g.nodes.new("NodeGroupOutput")
    mr = g.nodes.new("ShaderNodeMapRange")
    mr.interpolation_type = "SMOOTHSTEP"
    mr.inputs["To Min"].default_value, mr.inputs["To Max"].default_value = 0.15, 0.85
    g.links.new(gin.outputs[0], mr.inputs["Value"])
    g.links.new(mr.outputs["Result"], gout.inputs[0])
    return g


def nodes_utility():
    _reset()
    mat, nt, d = _material("Floor")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["Object"], sep.inputs[0])
    m = _node(nt, "ShaderNodeMath", {"operation": "PINGPONG"}, Value_001=0.7)
    nt.links.new(sep.outputs["X"], m.inputs[0])
    grp = nt.nodes.new("ShaderNodeGroup")
    grp.node_tree = _group()
    nt.links.new(m.outputs[0], grp.inputs[0])
    reroute = nt.nodes.new("NodeReroute")
    nt.links.new(grp.outputs[0], reroute.inputs[0])
    comb = _node(nt, "ShaderNodeCombineColor", {"mode": "HSV"}, Green=0.5, Blue=0.7)
    nt.links.new(reroute.outputs[0], comb.inputs["Red"])
    curves = nt.nodes.new("ShaderNodeRGBCurve")
    c = curves.mapping.curves[3]
    c.points.new(0.5, 0.35)
    curves.mapping.update()
    nt.links.new(comb.outputs[0], curves.inputs["Color"])
    nt.links.new(curves.outputs[0], d.inputs["Color"])
    _floor(mat)

    mat = bpy.data.materials.new("Rim")
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(n)
    mix = nt.nodes.new("ShaderNodeMixShader")
    lw = _node(nt, "ShaderNodeLayerWeight", Blend=0.35)
    nt.links.new(lw.outputs["Facing"], mix.inputs["Fac"])
    diff = _node(nt, "ShaderNodeBsdfDiffuse", Color=(0.2, 0.4, 0.8, 1))
    glossy = _node(nt, "ShaderNodeBsdfGlossy", Color=(0.9, 0.9, 0.9, 1), Roughness=0.3)
    nt.links.new(diff.outputs[0], mix.inputs[1])
    nt.links.new(glossy.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    _sphere(mat, -1.6)

    mat, nt, d = _material("Blend")
    vm = _node(nt, "ShaderNodeVectorMath", {"operation": "DISTANCE"})
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["Object"], vm.inputs[0])
    cl = _node(nt, "ShaderNodeClamp", Min=0.2, Max=0.9)
    nt.links.new(vm.outputs["Value"], cl.inputs["Value"])
    bc = _node(nt, "ShaderNodeBrightContrast", Bright=0.05, Contrast=0.3)
    gm = _node(nt, "ShaderNodeGamma", Gamma=1.4)
    inv = _node(nt, "ShaderNodeInvert", Fac=0.3)
    mx = _node(nt, "ShaderNodeMix", {"data_type": "RGBA", "blend_type": "OVERLAY"},
               A_Color=(0.6, 0.3, 0.5, 1))
    nt.links.new(cl.outputs[0], _ident(mx.inputs, "Factor_Float"))
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["Generated"],
                 _ident(mx.inputs, "B_Color"))
    nt.links.new(_ident(mx.outputs, "Result_Color"), bc.inputs["Color"])
    nt.links.new(bc.outputs[0], gm.inputs["Color"])
    nt.links.new(gm.outputs[0], inv.inputs["Color"])
    nt.links.new(inv.outputs[0], d.inputs["Color"])
    _sphere(mat, 0.0)

    mat, nt, e = _material("Glow", "ShaderNodeEmission")
    noise = _node(nt, "ShaderNodeTexNoise", Scale=4.0)
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.1, 0.02, 0.0, 1)
    ramp.color_ramp.elements[1].color = (1.0, 0.6, 0.2, 1)
    nt.links.new(noise.outputs["Fac"], ramp.inputs[0])
    nt.links.new(ramp.outputs["Color"], e.inputs["Color"])
    e.inputs["Strength"].default_value = 6.0
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(1.6, 0.6, 0.8),
                                     rotation=(math.radians(80), 0, 0))
    bpy.context.object.data.materials.append(mat)
    return bpy.context.scene


def _bump(nt, shader, height, distance, strength=1.0, invert=False):
    b = _node(nt, "ShaderNodeBump", {"invert": invert}, Distance=distance, Strength=strength)
    nt.links.new(height, b.inputs["Height"])
    nt.links.new(b.outputs[0], shader.inputs["Normal"])
    return b


def nodes_vector():
    """Bump (strength, distance, invert, a chain of two), the Displacement output as bump,
    Mapping (normal), Vector Math and Separate XYZ: the vector family."""
    _reset()
    mat, nt, d = _material("Floor")
    coord = nt.nodes.new("ShaderNodeTexCoord")
    mapping = _node(nt, "ShaderNodeMapping", Rotation=(0, 0, 0.3), Scale=(1.5, 1.5, 1.5))
    nt.links.new(coord.outputs["Object"], mapping.inputs["Vector"])
    chk = _node(nt, "ShaderNodeTexChecker", Scale=1.0, Color1=(0.75, 0.7, 0.6, 1),
                Color2=(0.35, 0.4, 0.45, 1))
    nt.links.new(mapping.outputs[0], chk.inputs["Vector"])
    nt.links.new(chk.outputs["Color"], d.inputs["Color"])
    noise = _node(nt, "ShaderNodeTexNoise", Scale=1.5, Detail=2.0)
    nt.links.new(mapping.outputs[0], noise.inputs["Vector"])
    _bump(nt, d, noise.outputs["Fac"], 0.4, strength=0.8)
    _floor(mat)

    mat, nt, d = _material("Waves")
    d.inputs["Color"].default_value = (0.7, 0.5, 0.3, 1)
    wave = _node(nt, "ShaderNodeTexWave", Scale=2.0)
    _bump(nt, d, wave.outputs["Fac"], 0.03, invert=True)
    _sphere(mat, -1.6)

    mat, nt, d = _material("Cells")
    mat.displacement_method = "BUMP"
    d.inputs["Color"].default_value = (0.4, 0.6, 0.7, 1)
    vor = _node(nt, "ShaderNodeTexVoronoi", Scale=4.0)
    disp = _node(nt, "ShaderNodeDisplacement", Midlevel=0.0, Scale=0.15)
    nt.links.new(vor.outputs["Distance"], disp.inputs["Height"])
    nt.links.new(disp.outputs[0], nt.nodes["Material Output"].inputs["Displacement"])
    _sphere(mat, 0.0)

    mat, nt, d = _material("Chained")
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    mp = _node(nt, "ShaderNodeMapping", {"vector_type": "NORMAL"}, Rotation=(0.4, 0, 0.9))
    nt.links.new(geo.outputs["Normal"], mp.inputs["Vector"])
    vm = _node(nt, "ShaderNodeVectorMath", {"operation": "MULTIPLY_ADD"},
               Vector_001=(0.35, 0.35, 0.35), Vector_002=(0.5, 0.5, 0.5))
    nt.links.new(mp.outputs[0], vm.inputs[0])
    nt.links.new(vm.outputs[0], d.inputs["Color"])
    n1 = _node(nt, "ShaderNodeTexNoise", Scale=3.0)
    b1 = _node(nt, "ShaderNodeBump", Distance=0.05)
    nt.links.new(n1.outputs["Fac"], b1.inputs["Height"])
    ripple = _node(nt, "ShaderNodeTexWave", {"bands_direction": "Z"}, Scale=3.0)
    b2 = _bump(nt, d, ripple.outputs["Fac"], 0.03, strength=0.6)
    nt.links.new(b1.outputs[0], b2.inputs["Normal"])
    _sphere(mat, 1.6)
    return bpy.context.scene


def nodes_input():
    """Geometry, Texture Coordinate, Object Info, Color Attribute and Attribute; the area light
    through a light node tree (Blackbody x strength)."""
    sc = _reset()
    lamp = bpy.data.lights["Area"]
    lamp.use_nodes = True
    lt = lamp.node_tree
    emit = next(n for n in lt.nodes if n.type == "EMISSION")
    bb = _node(lt, "ShaderNodeBlackbody", Temperature=4200.0)
    lt.links.new(bb.outputs[0], emit.inputs["Color"])
    emit.inputs["Strength"].default_value = 1.3

    mat, nt, d = _material("Floor")
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    vm = _node(nt, "ShaderNodeVectorMath", {"operation": "FRACTION"})
    nt.links.new(geo.outputs["Position"], vm.inputs[0])
    nt.links.new(vm.outputs[0], d.inputs["Color"])
    _floor(mat)

    mat, nt, d = _material("Coords")
    tc = nt.nodes.new("ShaderNodeTexCoord")
    mix = _node(nt, "ShaderNodeMix", {"data_type": "RGBA"}, Factor_Float=0.5)
    nt.links.new(tc.outputs["Generated"], _ident(mix.inputs, "A_Color"))
    nt.links.new(tc.outputs["UV"], _ident(mix.inputs, "B_Color"))
    nt.links.new(_ident(mix.outputs, "Result_Color"), d.inputs["Color"])
    _sphere(mat, -1.6)

    mat, nt, d = _material("Located")
    info = nt.nodes.new("ShaderNodeObjectInfo")
    tc = nt.nodes.new("ShaderNodeTexCoord")
    add = _node(nt, "ShaderNodeVectorMath", {"operation": "SUBTRACT"})
    nt.links.new(tc.outputs["Object"], add.inputs[0])
    nt.links.new(info.outputs["Location"], add.inputs[1])
    ab = _node(nt, "ShaderNodeVectorMath", {"operation": "ABSOLUTE"})
    nt.links.new(add.outputs[0], ab.inputs[0])
    nt.links.new(ab.outputs[0], d.inputs["Color"])
    _sphere(mat, 0.0)

    mat, nt, d = _material("Painted")
    ca = nt.nodes.new("ShaderNodeVertexColor")
    ca.layer_name = "Paint"
    nt.links.new(ca.outputs["Color"], d.inputs["Color"])
    _sphere(mat, 1.6)
    mesh = bpy.context.object.data
    attr = mesh.color_attributes.new("Paint", "FLOAT_COLOR", "POINT")
    for i, v in enumerate(mesh.vertices):
        x, y, z = v.co
        attr.data[i].color = (0.5 + 0.5 * x / 0.7, 0.3 + 0.4 * (z > 0), 0.6, 1.0)
    return sc


def nodes_world():
    """A procedural world (Gradient, Noise, ColorRamp, Mix into Background) baked into an
    environment map (addon/export/world_nodes.py); no other light."""
    sc = _reset()
    bpy.data.objects.remove(bpy.data.objects["Area"])
    nt = sc.world.node_tree
    bg = nt.nodes["Background"]
    tc = nt.nodes.new("ShaderNodeTexCoord")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(tc.outputs["Generated"], sep.inputs[0])
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].position = 0.45
    ramp.color_ramp.elements[0].color = (0.25, 0.2, 0.15, 1)
    ramp.color_ramp.elements[1].color = (0.3, 0.55, 1.0, 1)
    mr = _node(nt, "ShaderNodeMapRange", **{"From Min": -1.0})
    nt.links.new(sep.outputs["Z"], mr.inputs["Value"])
    nt.links.new(mr.outputs[0], ramp.inputs[0])
    noise = _node(nt, "ShaderNodeTexNoise", Scale=2.0)
    nt.links.new(tc.outputs["Generated"], noise.inputs["Vector"])
    mix = _node(nt, "ShaderNodeMix", {"data_type": "RGBA", "blend_type": "SCREEN"},
                Factor_Float=0.35)
    nt.links.new(ramp.outputs["Color"], _ident(mix.inputs, "A_Color"))
    nt.links.new(noise.outputs["Color"], _ident(mix.inputs, "B_Color"))
    nt.links.new(_ident(mix.outputs, "Result_Color"), bg.inputs["Color"])
    bg.inputs["Strength"].default_value = 1.5
    # Cycles' importance map of the world: 128 texels wide instead of its automatic 1024 (what
    # the map sets is Cycles' noise, not its image; the procedural world's map took 22 of
    # each Cycles render's 23 s)
    sc.world.cycles.sampling_method = "MANUAL"
    sc.world.cycles.sample_map_resolution = 128
    for name, x, col in (("Left", -1.6, (0.8, 0.8, 0.8, 1)), ("Mid", 0.0, (0.8, 0.3, 0.2, 1)),
                         ("Right", 1.6, (0.2, 0.6, 0.3, 1))):
        mat, _, d = _material(name)
        d.inputs["Color"].default_value = col
        _sphere(mat, x)
    mat, _, d = _material("Floor")
    _floor(mat)
    return sc


SCENES = {"nodes_procedural": nodes_procedural, "nodes_utility": nodes_utility,
          "nodes_vector": nodes_vector, "nodes_input": nodes_input, "nodes_world": nodes_world}

if __name__ == "__main__":
    SCENES[sys.argv[1]]()
    if len(sys.argv) > 2:
        bpy.ops.wm.save_as_mainfile(filepath=sys.argv[2])
