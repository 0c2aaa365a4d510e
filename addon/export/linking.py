"""Cycles' light linking (Object > Shading > Light Linking > Receiver Collection) as Lantern's
receiver sets (native/src/integrator/pt_light_linking.h, pt; the bidirectional integrators hand
such a scene to pt with a warning). As Blender's depsgraph decides: an emitter whose collection
includes some objects lights only those; one that only excludes lights every object but those
(a child collection's state applies to every object in it). Meshes with the same answer for
every linked emitter share a set (at most 64, as in Cycles); each linked emitter (a lamp or an
emissive mesh) carries the mask of the sets it lights. Shadow linking: unsupported.py warns."""


def _states(coll, out, state=None, seen=None):
    """Object name -> 'INCLUDE' / 'EXCLUDE' for every object in coll and its children (a child
    collection's state over its objects'; the first entry of an object wins)."""
    seen = seen if seen is not None else set()
    if coll is None or coll.name in seen:
        return out
    seen.add(coll.name)
    for obj, entry in zip(coll.objects, coll.collection_objects):
        out.setdefault(obj.name, state or entry.light_linking.link_state)
    for child, entry in zip(coll.children, coll.collection_children):
        _states(child, out, state or entry.light_linking.link_state, seen)
    return out


def _receiver_collection(obj):
    ll = getattr(obj, "light_linking", None)
    return getattr(ll, "receiver_collection", None) if ll is not None else None


class LightLinking:
    """Collects the exported meshes and lights of one export (by object name), then numbers
    the receiver sets in finish()."""

    def __init__(self, report):
        self.report = report
        self.meshes = []    # (object name, mesh dict)
        self.emitters = []  # (states of its receiver collection, the dict to carry the mask)

    def mesh(self, obj, mesh):
        self.meshes.append((obj.name, mesh))
        coll = _receiver_collection(obj)
        if coll is not None:
            self.emitters.append((_states(coll, {}), mesh))

    def light(self, obj, light):
        coll = _receiver_collection(obj)
        if coll is not None:
            self.emitters.append((_states(coll, {}), light))

    def finish(self):
        if not self.emitters:
            return

        def lights(states, name):
            include = any(s == "INCLUDE" for s in states.values())
            state = states.get(name)
            return state == "INCLUDE" if include else state != "EXCLUDE"

        sets = {tuple(True for _ in self.emitters): 0}  # set 0: lit by every linked emitter
        for name, mesh in self.meshes:
            key = tuple(lights(states, name) for states, _ in self.emitters)
            if key not in sets:
                if len(sets) == 64:
                    self.report.warn(f"Object '{name}': more than 64 light linking receiver "
                                     "sets; it is lit as the objects of set 0")
                    key = next(iter(sets))
                else:
                    sets[key] = len(sets)
            if sets[key]:
                mesh["light_set"] = sets[key]
        for e, (_, target) in enumerate(self.emitters):
            target["receivers"] = sum(1 << s for key, s in sets.items() if key[e])
