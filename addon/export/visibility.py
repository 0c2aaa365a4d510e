"""Cycles' object ray visibility (Object > Visibility > Ray Visibility): Camera and Shadow are
the mesh's visible_camera / cast_shadow (every integrator); Diffuse, Glossy, Transmission and
Volume Scatter are exported here, as mesh fields present only when off, and rendered by pt
(native/src/integrator/pt_ray_visibility.h) and, on surfaces, by bdpt, lvc, cis
(bidir_ray_visibility.h) and lt (lt_ray_visibility.h); what they leave to pt (beside media,
subsurface scattering; under lt beside linking, Cast Shadow off, strands) is handed over with a
warning (allocation.cpp bidir_visibility_reason). Strand sets take the same fields from their
object (export/walk.py; particle hair its emitter's, as Cycles syncs it). Indirect Only
collections: camera_visible below. A lamp's own flags are the same fields on its light
(export/light.py); the world's: world.py (pt only)."""

# (object property, scene field, label)
RAY_KINDS = (("visible_diffuse", "visible_diffuse", "Diffuse"),
             ("visible_glossy", "visible_glossy", "Glossy"),
             ("visible_transmission", "visible_transmission", "Transmission"),
             ("visible_volume_scatter", "visible_volume_scatter", "Volume Scatter"))


def _layer_flag(obj, getter, view_layer):
    """obj's view-layer flag `getter` (holdout_get, indirect_only_get), read on the original
    object (the evaluated copy has no view-layer base and reads False); False without a layer."""
    original = getattr(obj, "original", obj)
    if view_layer is None or not hasattr(original, getter):
        return False
    try:
        return bool(getattr(original, getter)(view_layer=view_layer))
    except (TypeError, RuntimeError, ReferenceError):
        return False


def camera_visible(inst, view_layer):
    """The Camera ray visibility of depsgraph instance inst, as Cycles' object sync sets it:
    the object's visible_camera, cleared when its instancer (the object itself when it is no
    instance) is Indirect Only in the view layer (a collection's Indirect Only flag) and not a
    holdout (a holdout keeps its camera rays). Only the camera loses it: diffuse, glossy,
    transmission, volume scatter and shadow rays see the object as before."""
    obj = inst.object
    if not getattr(obj, "visible_camera", True):
        return False
    parent = inst.parent if getattr(inst, "is_instance", False) and inst.parent else obj
    if getattr(parent, "is_holdout", False) or _layer_flag(parent, "holdout_get", view_layer):
        return True
    return not _layer_flag(parent, "indirect_only_get", view_layer)


def mesh_ray_visibility(obj):
    """The mesh fields of obj's ray visibility that are off (an empty dict when all are on, so
    that a scene without them exports as before)."""
    return {field: False for prop, field, _ in RAY_KINDS if not getattr(obj, prop, True)}


def mixed_kind_warning(meshes, materials, report):
    """Principled materials scatter diffuse and glossy rays as one mixture in Lantern
    (pt_scatter_kind): an object hidden from one of the two kinds only stays visible in their
    reflections, where Cycles hides it from the lobe of that kind. (A Mix Shader's ray takes
    the kind of the leaf it sampled, as Cycles: pt_sampled_leaf; its Principled leaves, which
    `materials` lists, are named.) Named, once."""
    one_kind = [m.get("name", "?") for m in meshes
                if m.get("visible_diffuse", True) != m.get("visible_glossy", True)]
    mixed = [m.get("name", "?") for m in materials if m.get("type") == "principled"]
    if one_kind and mixed:
        report.warn(f"Object '{one_kind[0]}'{' and others' if len(one_kind) > 1 else ''}: "
                    "hidden from diffuse or glossy rays only; Principled materials "
                    f"({', '.join(mixed[:3])}{', ...' if len(mixed) > 3 else ''}) see it in "
                    "every reflection")


def mixed_kind_lamp_warning(lights, materials, report):
    """A lamp hidden from diffuse or glossy rays only gives a Principled surface, which Lantern
    samples as one mixture of both kinds, none of its light (pt_light_hidden: any kind of the
    scattering's off), where Cycles hides it from the lobe of that kind only. (A Mix Shader's
    leaves each take their own kind and class, as Cycles: pt_nee_leaves; its Principled
    leaves are named.) Named, once."""
    one_kind = [li.get("name", "?") for li in lights
                if li.get("visible_diffuse", True) != li.get("visible_glossy", True)]
    mixed = [m.get("name", "?") for m in materials if m.get("type") == "principled"]
    if one_kind and mixed:
        report.warn(f"Light '{one_kind[0]}'{' and others' if len(one_kind) > 1 else ''}: "
                    "hidden from diffuse or glossy rays only; Principled materials "
                    f"({', '.join(mixed[:3])}{', ...' if len(mixed) > 3 else ''}) get none of "
                    "its light")
