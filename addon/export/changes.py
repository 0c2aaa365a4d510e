"""What changed since the last viewport sync, as bit flags, from the depsgraph's updates
(as Cycles' sync_recalc reads them). Measured with bpy 5.0.1, what an edit tags:

- moving an object: the Object (transform); a camera: the camera Object (transform);
- a material's node value: the Material, and the Objects and Meshes using it (shading only);
- a world's node value: the World; a light's energy: the Light data and its Object;
- a mesh edit or a new material in a slot: the Object (geometry);
- hiding, adding, deleting objects, render settings: the Scene (and Collections);
- an object's own settings (ray visibility, shadow catcher, Object Info colour, pass index):
  the Object alone (shading only), as a material edit tags its objects: `objects` names them
  and the sync compares what it read from them (export/sync.py, OBJECTS).

Anything else (an ID type not listed here, or an update without any ID) is FULL: export all."""

VIEW = 1 << 0       # the view or the camera: replace the camera, nothing re-exported
SETTINGS = 1 << 1   # the Scene (settings, visibility, objects added or removed)
WORLD = 1 << 2
MATERIALS = 1 << 3  # .materials: their names; .all_materials: a node group changed
LIGHTS = 1 << 4
GEOMETRY = 1 << 5   # .geometry: objects whose meshes are extracted again
TRANSFORM = 1 << 6  # instances moved: placed again from their cached arrays
IMAGES = 1 << 7     # .images: their pixels are read again
FULL = 1 << 8       # everything is exported again
OBJECTS = 1 << 9    # objects' own settings changed (set by the sync): walked, none extracted

NAMES = {VIEW: "view", SETTINGS: "settings", WORLD: "world", MATERIALS: "materials",
         LIGHTS: "lights", GEOMETRY: "geometry", TRANSFORM: "transform", IMAGES: "images",
         FULL: "full", OBJECTS: "objects"}

_GEOMETRY_DATA = {"Mesh", "Curve", "SurfaceCurve", "TextCurve", "MetaBall", "Curves",
                  "PointCloud", "Volume", "Lattice", "Key", "GreasePencilv3", "GreasePencil"}
_IGNORED = {"Screen", "WorkSpace", "WindowManager", "Text", "Brush", "Palette", "Library",
            "Action", "Armature", "Annotation", "Mask", "MovieClip", "Sound", "VectorFont",
            "PaintCurve", "CacheFile", "LightProbe", "Speaker", "FreestyleLineStyle",
            "Camera", "ParticleSettings", "GeometryNodeTree", "CompositorNodeTree",
            "TextureNodeTree"}


class Changes:
    """Accumulated changes: `flags` and the names they concern. `a |= b` merges."""

    def __init__(self, flags=0):
        self.flags = flags
        self.materials, self.geometry, self.images = set(), set(), set()
        self.objects = set()  # objects tagged for shading only (their settings, or a material)
        self.all_materials = False

    def __ior__(self, other):
        self.flags |= other.flags
        self.materials |= other.materials
        self.geometry |= other.geometry
        self.images |= other.images
        self.objects |= other.objects
        self.all_materials |= other.all_materials
        return self

    def __bool__(self):
        return self.flags != 0

    def has(self, flag):
        return bool(self.flags & flag)

    def only_view(self):
        return self.flags == VIEW

    def __repr__(self):
        names = [n for f, n in NAMES.items() if self.flags & f] or ["none"]
        return f"<Changes {'|'.join(names)} materials={sorted(self.materials)} " \
               f"geometry={sorted(self.geometry)}>"


def _kind(uid):
    rna = getattr(uid, "bl_rna", None)
    if rna is None:
        return None
    base = getattr(rna, "base", None)
    if base is not None and base.identifier == "Light":
        return "Light"
    return rna.identifier


def _name(uid):
    original = getattr(uid, "original", None) or uid
    return getattr(original, "name_full", getattr(uid, "name", ""))


def classify(updates):
    """Changes from an iterable of depsgraph updates (DepsgraphUpdate: id,
    is_updated_geometry, is_updated_transform, is_updated_shading). No updates at all:
    FULL (a caller that cannot say what changed)."""
    ch = Changes()
    seen = False
    for u in updates:
        seen = True
        uid = getattr(u, "id", None)
        kind = _kind(uid) if uid is not None else None
        if kind is None:
            ch.flags |= FULL
        elif kind == "Object":
            otype = getattr(uid, "type", "")
            if otype == "LIGHT":
                ch.flags |= LIGHTS
            elif otype == "CAMERA":
                ch.flags |= VIEW
            elif getattr(u, "is_updated_geometry", False):
                ch.flags |= GEOMETRY
                ch.geometry.add(_name(uid))
            elif getattr(u, "is_updated_transform", False):
                ch.flags |= TRANSFORM
            else:  # shading only: a material of it (tagged itself) or its own settings
                ch.objects.add(_name(uid))
        elif kind == "Material":
            ch.flags |= MATERIALS
            ch.materials.add(_name(uid))
        elif kind == "World":
            ch.flags |= WORLD
        elif kind == "Light":
            ch.flags |= LIGHTS
        elif kind == "Image":
            ch.flags |= IMAGES
            ch.images.add(_name(uid))
        elif kind == "ShaderNodeTree":
            if not getattr(uid, "is_embedded_data", True):  # a node group: who uses it?
                ch.flags |= MATERIALS | WORLD
                ch.all_materials = True
        elif kind in ("Scene", "Collection"):
            ch.flags |= SETTINGS
        elif kind in _GEOMETRY_DATA or kind in _IGNORED:
            pass  # their objects are tagged (geometry data), or they do not render
        else:
            ch.flags |= FULL
    if not seen:
        ch.flags |= FULL
    return ch
