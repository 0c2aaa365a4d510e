"""Cycles' light and shadow linking (Object > Shading > Light Linking: Receiver and Blocker
Collections) as Lantern's receiver and blocker sets (native/src/integrator/pt_light_linking.h,
pt; bdpt, lvc, cis: bidir_linking.h; lt: lt_linking.h; the few combinations they leave to pt
are handed over with a warning, allocation.cpp bidir_visibility_reason). As Blender's
depsgraph decides: an emitter whose collection includes some objects lights (is shadowed by)
only those; one that only excludes, every object but those (a child collection's state applies
to every object in it). Meshes and strand sets (a Curves object's, a mesh's particle hair: its
object's) with the same answer for every linked emitter share a set (at
most 64, as in Cycles; set 0 is that of an object in no collection, which pt gives a world
volume's points too); each linked emitter (a lamp or an emissive mesh) carries the mask of
the sets it lights (receivers) or that shadow it (blockers)."""


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


def _collection(obj, attr):
    ll = getattr(obj, "light_linking", None)
    return getattr(ll, attr, None) if ll is not None else None


class LightLinking:
    """Collects the exported meshes and lights of one export (by object name), then numbers
    the sets in finish(): receiver sets (mesh "light_set", emitter "receivers") and blocker sets
    (mesh "shadow_set", emitter "blockers")."""

    KINDS = (("receiver_collection", "light_set", "receivers", "light linking"),
             ("blocker_collection", "shadow_set", "blockers", "shadow linking"))

    def __init__(self, report):
        self.report = report
        self.meshes = []    # (object name, mesh dict)
        self.emitters = {k[0]: [] for k in self.KINDS}  # (collection states, emitter dict)

    def _emitter(self, obj, target):
        for attr, *_ in self.KINDS:
            coll = _collection(obj, attr)
            if coll is not None:
                self.emitters[attr].append((_states(coll, {}), target))

    def mesh(self, obj, mesh):
        self.meshes.append((obj.name, mesh))
        self._emitter(obj, mesh)

    def light(self, obj, light):
        self._emitter(obj, light)

    def curves(self, obj, sets):
        """An object's strand sets (a Curves object's, a mesh's particle hair): its object's
        receiver and blocker sets, as Cycles links a hair's segments through their object."""
        self.meshes += [(obj.name, st) for st in sets]

    def finish(self):
        for attr, set_field, mask_field, what in self.KINDS:
            self._number(self.emitters[attr], set_field, mask_field, what)

    def _number(self, emitters, set_field, mask_field, what):
        if not emitters:
            return

        def lights(states, name):
            include = any(s == "INCLUDE" for s in states.values())
            state = states.get(name)
            return state == "INCLUDE" if include else state != "EXCLUDE"

        # set 0: an object in no emitter's collection (as Cycles' set 0, the set of an object
        # without linking and of a world volume, OBJECT_NONE): lit by an Exclude-only emitter,
        # not by one whose collection includes some objects
        sets = {tuple(lights(states, None) for states, _ in emitters): 0}
        for name, mesh in self.meshes:
            key = tuple(lights(states, name) for states, _ in emitters)
            if key not in sets:
                if len(sets) == 64:
                    self.report.warn(f"Object '{name}': more than 64 {what} sets; it is "
                                     "linked as the objects of set 0")
                    key = next(iter(sets))
                else:
                    sets[key] = len(sets)
            if sets[key]:
                mesh[set_field] = sets[key]
        for e, (_, target) in enumerate(emitters):
            target[mask_field] = sum(1 << s for key, s in sets.items() if key[e])
