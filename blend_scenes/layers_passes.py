"""The scene of issue 17's checks against Cycles: two view layers with their own collections and
passes, and a border. The stage of scenes.py (grey floor, blue-grey back wall, an orange
Principled box, a green Diffuse block) lit by a 300 W square area light; 64 x 64 pixels.

- collection "Set": floor, back wall, box; collection "Props": the block;
- view layer "Full" renders both, "NoProps" excludes "Props" (the block's shadow and its
  light bounced onto the floor disappear with it);
- both layers ask for Depth, Normal, Diffuse Color, Emission and the denoising data (Cycles'
  and Lantern's switch);
- the border (not switched on here) covers x 0.2-0.7, y 0.15-0.65 of the frame.

    .venv/bin/python blend_scenes/layers_passes.py [out.blend]"""

import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scenes  # noqa: E402

RES = 64
BORDER = (0.2, 0.7, 0.15, 0.65)  # min x, max x, min y, max y


def _collect(name, objects):
    col = bpy.data.collections.new(name)
    bpy.context.scene.collection.children.link(col)
    for obj in objects:
        for c in list(obj.users_collection):
            c.objects.unlink(obj)
        col.objects.link(obj)
    return col


def set_border(scene, crop):
    r = scene.render
    r.use_border, r.use_crop_to_border = True, crop
    r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = BORDER


def layers_passes():
    scene = scenes._reset()
    scene.render.resolution_x = scene.render.resolution_y = RES
    scenes._stage()
    scenes.light("AREA", "Area", (0.3, -1.2, 2.8), target=(0, 0.3, 0), shape="SQUARE",
                 size=0.8, energy=300.0)
    objs = bpy.data.objects
    _collect("Set", [objs["Floor"], objs["Back"], objs["Box"]])
    _collect("Props", [objs["Block"]])
    full = scene.view_layers[0]
    full.name = "Full"
    no_props = scene.view_layers.new("NoProps")
    no_props.layer_collection.children["Props"].exclude = True
    for vl in (full, no_props):
        vl.use_pass_z = vl.use_pass_normal = True
        vl.use_pass_diffuse_color = vl.use_pass_emit = True
        vl.cycles.denoising_store_passes = True
        if hasattr(vl, "lantern"):
            vl.lantern.denoising_store_passes = True
    return scene


def build(path=None):
    layers_passes()
    path = path or os.path.join(scenes.OUT_DIR, "layers_passes.blend")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=path, check_existing=False)
    return path


if __name__ == "__main__":
    print(build(sys.argv[1] if len(sys.argv) > 1 else None))
