"""The add-on's numbering of light / shadow linking sets (addon/export/linking.py) against
Cycles' rule: set 0 is the set of an object in no emitter's collection (Cycles' receiver set 0:
an object without linking, and a world volume's point, OBJECT_NONE), which an emitter whose
collection includes some objects does not light and an Exclude-only emitter does. Anything the
export gives no set (strands, a world volume's points in pt) reads set 0, so the rule decides
what they receive (difftest4: cis 10014's strands lit by an Include-linked spot, +95-224 %;
the hand-made scene's fog, +17-20 %). Fakes of bpy's objects: no Blender needed."""
import importlib.util
import os
from types import SimpleNamespace as NS

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _linking():
    spec = importlib.util.spec_from_file_location(
        "lantern_export_linking", os.path.join(ROOT, "addon", "export", "linking.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _coll(name, objects, state):
    return NS(name=name, objects=objects,
              collection_objects=[NS(light_linking=NS(link_state=state)) for _ in objects],
              children=[], collection_children=[])


def _obj(name, receivers=None, blockers=None):
    return NS(name=name, light_linking=NS(receiver_collection=receivers,
                                          blocker_collection=blockers))


class _Report:
    def __init__(self):
        self.warnings = []

    def warn(self, msg):
        self.warnings.append(msg)


def _numbered(emitters, mesh_names):
    linking = _linking().LightLinking(_Report())
    meshes = {}
    for name in mesh_names:
        meshes[name] = {}
        linking.mesh(_obj(name), meshes[name])
    lights = {}
    for obj in emitters:
        lights[obj.name] = {}
        linking.light(obj, lights[obj.name])
    linking.finish()
    return meshes, lights


def _lights(mask, mesh, field="light_set"):
    return (mask >> mesh.get(field, 0)) & 1 == 1


def test_include_emitter_does_not_light_set_zero():
    ball = _obj("ball")
    key = _obj("key", receivers=_coll("key_recv", [ball], "INCLUDE"))
    meshes, lights = _numbered([key], ["ball", "floor"])
    mask = lights["key"]["receivers"]
    assert _lights(mask, meshes["ball"])
    assert not _lights(mask, meshes["floor"])
    assert "light_set" not in meshes["floor"]      # the floor: an object in no collection
    assert not mask & 1, "set 0 (unexported strands, world fog) lit by an Include emitter"


def test_exclude_emitter_lights_set_zero():
    floor = _obj("floor")
    key = _obj("key", receivers=_coll("key_recv", [floor], "EXCLUDE"))
    meshes, lights = _numbered([key], ["ball", "floor"])
    mask = lights["key"]["receivers"]
    assert _lights(mask, meshes["ball"]) and mask & 1
    assert not _lights(mask, meshes["floor"])


def test_blocker_sets_follow_the_same_rule():
    ball = _obj("ball")
    key = _obj("key", blockers=_coll("key_block", [ball], "INCLUDE"))
    meshes, lights = _numbered([key], ["ball", "floor"])
    mask = lights["key"]["blockers"]
    assert _lights(mask, meshes["ball"], "shadow_set")
    assert not mask & 1   # an object in no collection casts this key no shadow
