"""Transform motion blur (docs/motion_blur.md): with Render > Motion Blur on, every moving
object's world matrix (and the camera's) at the shutter's steps, read as Cycles reads them:
the shutter (Render > Motion Blur > Shutter, in frames) opens at the frame (Position Start),
around it (Center) or closes at it (End); an object with Motion Blur on (Object Properties >
Motion Blur) takes 2^(Steps - 1) x 2 + 1 evenly spread steps, the camera too. The steps are
read by setting the scene to each step's subframe (`frame_set`: the render engine's own during a
render), then back to the frame. Meshes keep their positions as exported at the frame with the
matrix they were exported with (`motion_base`); the core interpolates the steps per ray.
Deformation (armatures, shape keys, modifiers that move vertices), as Cycles' deformation blur
(Object Properties > Motion Blur > Deformation): an object whose evaluated mesh keeps its vertex
count at every step and whose vertices move carries its corners' positions at the steps,
placed by the matrix it was exported with (`mesh["deform"]`); a vertex count that changes leaves
it still, with a warning naming it (as Cycles). Hair (Curves objects, particle hair) of an
object with Motion Blur on is exported again at each step: its world-space points (and radii)
at the steps (`curves["deform"]`, `["deform_radius"]`) where they move, transform and
deformation alike (the core lerps them), except where the object's matrix turns or scales
(docs/motion_blur.md "Strands of a turning object"): then, as Cycles keeps a moving object's
curves in object space, the strands keep their points as exported with the object's matrices
(`curves["motion"]`, `["motion_base"]`, slerped by the core as a mesh's) and carry `deform`
only where the points also move in that frame. An object that only translates keeps world
points at the steps (a lerp of the points is then the matrix's own: the same bits as before)."""

import math

import numpy as np

POSITION_OFFSET = {"START": 0.5, "CENTER": 0.0, "END": -0.5}  # x shutter: the middle's offset


def motion_enabled(bscene):
    return bool(getattr(bscene.render, "use_motion_blur", False))


def object_steps(obj, instancer=None):
    """How many steps obj takes (0: its motion blur is off), as Cycles: the object's Motion
    Steps s gives 2^(s - 1) x 2 + 1 (3, 5, 9, ...), an instancer's larger count wins."""
    def own(o):
        c = getattr(o, "cycles", None)
        if c is None:
            return 3
        if not getattr(c, "use_motion_blur", True):
            return 0
        return (2 << (max(1, int(getattr(c, "motion_steps", 1))) - 1)) + 1
    n = own(obj)
    if n and instancer is not None and instancer is not obj:
        m = own(instancer)
        n = max(n, m) if m else 0
    return n


def step_offsets(bscene, n):
    """Frame offsets (from the current frame) of n steps over the shutter."""
    r = bscene.render
    shutter = float(r.motion_blur_shutter)
    middle = POSITION_OFFSET.get(getattr(r, "motion_blur_position", "CENTER"), 0.0) * shutter
    return [middle + shutter * (-0.5 + i / (n - 1)) for i in range(n)]


def instance_key(inst):
    obj = inst.object
    if inst.is_instance:
        return (obj.name, tuple(inst.persistent_id), inst.parent.name if inst.parent else "")
    return (obj.name,)


def _deforms(obj):
    """Whether obj's vertices may move over the shutter (not blurred: a warning)."""
    c = getattr(obj, "cycles", None)
    if c is not None and not getattr(c, "use_deform_motion", True):
        return False
    data = getattr(obj, "data", None)
    keys = getattr(data, "shape_keys", None)
    if keys is not None and (keys.animation_data is not None or len(keys.key_blocks) > 1):
        return True
    return any(m.type in {"ARMATURE", "MESH_DEFORM", "LATTICE", "CURVE", "HOOK", "CAST",
                          "DISPLACE", "WAVE", "OCEAN", "SIMPLE_DEFORM", "SMOOTH",
                          "SURFACE_DEFORM", "WARP", "NODES", "MESH_CACHE",
                          "MESH_SEQUENCE_CACHE", "CLOTH", "SOFT_BODY"}
               for m in getattr(obj, "modifiers", ()))


class MotionRecorder:
    """Collects the exported meshes that may move, then reads their steps (finish)."""

    def __init__(self, depsgraph, report, frame_set=None, final=True):
        self.depsgraph = depsgraph
        self.report = report
        self.bscene = depsgraph.scene_eval
        self.on = final and motion_enabled(self.bscene)
        self.frame_set = frame_set or depsgraph.scene.frame_set
        self._meshes = {}  # key -> (mesh dict, steps)
        self._deform = {}  # key -> (object, mesh dict, steps, corners, matrix at the frame)
        self._strands = {}  # key -> (object name, strand set dicts, steps, their exporter)
        self._strand_base = {}  # key -> the instance's matrix the sets were exported with

    def _moving(self, inst):
        """(steps, key) of an instance that motion blur exports at its shutter steps, or None
        (blur off, or the object does not move)."""
        if not self.on:
            return None
        n = object_steps(inst.object, inst.parent if inst.is_instance else None)
        return (n, instance_key(inst)) if n >= 2 else None

    def mesh(self, inst, mesh, corners=None):
        """A mesh exported from inst; corners: (the vertex of each exported corner, the
        evaluated mesh's vertex count) for deformation blur (mesh.py MeshExporter.corners)."""
        moving = self._moving(inst)
        if moving is None:
            return
        n, key = moving
        obj = inst.object
        if key in self._meshes:  # the same key twice: leave both still
            self._meshes[key] = (None, 0)
            self._deform.pop(key, None)
            return
        mesh["motion_base"] = np.array(inst.matrix_world, dtype=np.float64).tolist()
        self._meshes[key] = (mesh, n)
        if _deforms(obj):
            if inst.is_instance or corners is None:
                self.report.warn(f"Object '{obj.name}': deformation motion blur of instances is "
                                 "not rendered (its transform is blurred, its vertices stay as "
                                 "at the frame)")
            else:
                self._deform[key] = (obj.original, mesh, n, corners,
                                     np.array(inst.matrix_world, dtype=np.float64))

    def strands(self, inst, sets, export):
        """Strand sets exported from inst (export/strands.py); export(inst) exports them again
        at each step (docs/motion_blur.md "Strands"): points and radii at the steps, in world
        space, where the object moves or its hair deforms."""
        moving = self._moving(inst)
        if moving is None:
            return
        n, key = moving
        obj = inst.object
        if key in self._strands:  # the same key twice: leave both still
            self._strands[key] = (obj.name, None, 0, None)
            return
        self._strands[key] = (obj.name, sets, n, export)
        self._strand_base[key] = np.array(inst.matrix_world, dtype=np.float64)

    def finish(self, scene, camera_obj, camera_matrix):
        """Reads the steps and writes mesh["motion"] and scene.camera["motion"];
        camera_matrix(obj) is the exported camera's to_world of obj now."""
        if not self.on:
            return
        cam_n = object_steps(camera_obj) if camera_obj is not None else 0
        counts = {n for _, n in self._meshes.values() if n >= 2}
        counts |= {v[2] for v in self._strands.values() if v[2] >= 2}
        if cam_n >= 2:
            counts.add(cam_n)
        if not counts:
            return
        bscene = self.bscene
        frame, sub0 = bscene.frame_current, float(getattr(bscene, "frame_subframe", 0.0))
        offsets = sorted({round(o, 9) for n in counts for o in step_offsets(bscene, n)})
        at = {}  # offset -> {key: matrix}, "camera": matrix
        try:
            for off in offsets:
                t = frame + sub0 + off
                f = math.floor(t)
                self.frame_set(int(f), subframe=float(t - f))
                mats = {}
                for inst in self.depsgraph.object_instances:
                    key = instance_key(inst)
                    if key in self._meshes:
                        mats[key] = np.array(inst.matrix_world, dtype=np.float64)
                    if self._strands.get(key, (0, None))[1] is not None:
                        mats[("strands",) + key] = self._strands[key][3](inst)
                        mats[("strand matrix",) + key] = np.array(inst.matrix_world,
                                                                  dtype=np.float64)
                if cam_n >= 2:
                    cam_eval = camera_obj.evaluated_get(self.depsgraph)
                    mats["camera"] = np.asarray(camera_matrix(cam_eval), dtype=np.float64)
                for key, (obj, _, _, corners, _) in self._deform.items():
                    mats[("deform",) + key] = self._vertices(obj, corners[1])
                at[off] = mats
        finally:
            self.frame_set(int(frame), subframe=sub0)
        for key, (mesh, n) in self._meshes.items():
            if mesh is None:
                continue
            steps = [at[round(o, 9)].get(key) for o in step_offsets(bscene, n)]
            if any(s is None for s in steps):
                continue  # gone at some step: left still
            if all(np.array_equal(steps[0], s) for s in steps[1:]):
                mesh.pop("motion_base", None)
                continue
            mesh["motion"] = [s.tolist() for s in steps]
        for key, deform in self._deform.items():
            self._write_deform(deform, [at[round(o, 9)].get(("deform",) + key)
                                        for o in step_offsets(bscene, deform[2])])
        for key, (name, sets, n, _) in self._strands.items():
            if sets is not None:
                offs = [round(o, 9) for o in step_offsets(bscene, n)]
                write_strand_steps(name, sets, [at[o].get(("strands",) + key) for o in offs],
                                   self.report,
                                   [at[o].get(("strand matrix",) + key) for o in offs],
                                   self._strand_base.get(key))
        if cam_n >= 2:
            steps = [at[round(o, 9)]["camera"] for o in step_offsets(bscene, cam_n)]
            if not all(np.array_equal(steps[0], s) for s in steps[1:]):
                scene.camera["motion"] = [s.tolist() for s in steps]
        for mesh, _ in self._meshes.values():
            if mesh is not None and "motion" not in mesh:
                mesh.pop("motion_base", None)

    def _vertices(self, obj, count):
        """obj's evaluated vertex positions now (object space, float32 (V, 3)), or the vertex
        count where it is not `count` (a changed topology), or None (no geometry)."""
        ob = obj.evaluated_get(self.depsgraph)
        try:
            mesh = ob.to_mesh()
        except RuntimeError:
            return None
        try:
            if mesh is None:
                return None
            nv = len(mesh.vertices)
            if nv != count:
                return nv
            co = np.empty(nv * 3, np.float32)
            mesh.vertices.foreach_get("co", co)
            return co.reshape(nv, 3)
        finally:
            ob.to_mesh_clear()

    def _write_deform(self, deform, steps):
        """mesh["deform"]: the corners' positions at each step, placed as exported (the same
        float32 arithmetic as mesh.py), where the vertex count holds and some vertex moves."""
        obj, mesh, _, (corner_vert, count), m = deform
        if any(s is None for s in steps):
            return
        changed = [s for s in steps if isinstance(s, int)]
        if changed:
            self.report.warn(f"Object '{obj.name}': its vertex count changes over the shutter "
                             f"({count} at the frame, {changed[0]} at a motion step); rendered "
                             "without deformation motion blur")
            return
        if all(np.array_equal(steps[0], s) for s in steps[1:]):
            return
        lin, t = m[:3, :3].T.astype(np.float32), m[:3, 3].astype(np.float32)
        if len(mesh["positions"]) != len(corner_vert):
            return  # not the corners exported (cannot happen: mesh.py keeps every corner)
        mesh["deform"] = np.ascontiguousarray(
            np.stack([s[corner_vert] @ lin + t for s in steps]), np.float32)


def _turns(matrices, base):
    """Whether the object's matrices at the steps turn or scale it (their 3x3 parts differ)."""
    if base is None or not matrices or any(m is None for m in matrices):
        return False
    return any(not np.array_equal(m[:3, :3], matrices[0][:3, :3]) for m in matrices[1:])


def write_strand_steps(name, sets, steps, report, matrices=None, base=None):
    """set["deform"] (S, P, 3) and, where the radii change, set["deform_radius"] (S, P): each
    set's points at the steps (steps[k]: the sets exported again at step k, or None where the
    object is gone), where every step has the frame's strands and keys (offsets) and something
    moves; a count that changes leaves the strands still with a warning naming the object, as
    Cycles turns its deformation blur off. matrices: the object's world matrices at the steps,
    base: the one the sets were exported with; where they turn or scale it, set["motion"] and
    set["motion_base"], and deform (placed as exported) only where the points move in the
    object's frame (docs/motion_blur.md "Strands of a turning object")."""
    if any(s is None for s in steps):
        return
    turning = _turns(matrices, base)
    if turning:  # world at step k -> as exported (base M_k^-1), and its scale for the radii
        frame = [base @ np.linalg.inv(m) for m in matrices]
        scale = [abs(np.linalg.det(f[:3, :3])) ** (1.0 / 3.0) for f in frame]
    for j, st in enumerate(sets):
        at = [s[j] if j < len(s) else None for s in steps]
        if any(a is None or not np.array_equal(a["offsets"], st["offsets"]) for a in at):
            got = next((len(a["points"]) for a in at if a is not None), 0)
            report.warn(f"Object '{name}': its hair's strand or key count changes over the "
                        f"shutter ({len(st['points'])} points at the frame, {got} at a motion "
                        "step); its strands rendered without motion blur")
            continue
        if turning:
            _write_turning_steps(st, at, matrices, base, frame, scale)
            continue
        pts = np.stack([a["points"] for a in at]).astype(np.float32)
        rad = np.stack([a["radius"] for a in at]).astype(np.float32)
        if not all(np.array_equal(pts[0], p) for p in pts[1:]):
            st["deform"] = np.ascontiguousarray(pts)
        # radii: read again from the points' arc fractions, which rounding moves by an ulp
        if np.abs(rad[1:] - rad[0]).max(initial=0.0) > 1e-5 * np.abs(rad[0]).max(initial=0.0):
            st["deform_radius"] = np.ascontiguousarray(rad)
            st.setdefault("deform", np.ascontiguousarray(pts))


def _write_turning_steps(st, at, matrices, base, frame, scale):
    """A turning object's set st: its matrices, and its points (radii) at the steps brought to
    where they were exported, kept as deform only where they move there beyond float rounding."""
    st["motion"] = [np.asarray(m, np.float64).tolist() for m in matrices]
    st["motion_base"] = np.asarray(base, np.float64).tolist()
    pts = np.stack([np.asarray(a["points"], np.float64) @ f[:3, :3].T + f[:3, 3]
                    for a, f in zip(at, frame)])
    rad = np.stack([np.asarray(a["radius"], np.float64) * s for a, s in zip(at, scale)])
    p0 = np.asarray(st["points"], np.float64)
    r0 = np.asarray(st["radius"], np.float64)
    tol = 1e-5 * (1.0 + np.abs(p0).max(initial=0.0))
    if np.abs(pts - p0).max(initial=0.0) > tol:
        st["deform"] = np.ascontiguousarray(pts, np.float32)
    if np.abs(rad - r0).max(initial=0.0) > 1e-5 * np.abs(r0).max(initial=0.0):
        st["deform_radius"] = np.ascontiguousarray(rad, np.float32)
        st.setdefault("deform", np.ascontiguousarray(pts, np.float32))
