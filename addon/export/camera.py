"""Camera and film, as Cycles syncs them from Blender: sensor fit, lens or ortho scale, shift in
units of the fitted (larger) dimension, clipping along the view axis. The view window is given on
the z = -1 plane (perspective) or in metres (orthographic); see docs/scene_format.md."""

import numpy as np


def export_film(bscene):
    r = bscene.render
    pct = r.resolution_percentage / 100.0
    width = max(1, int(r.resolution_x * pct))
    height = max(1, int(r.resolution_y * pct))
    return {"width": width, "height": height, "filter_width": float(r.filter_size),
            "transparent": bool(r.film_transparent)}


def film_unsupported(bscene, report):
    """Film settings that change the image and that Lantern does not honour, named."""
    c = getattr(bscene, "cycles", None)
    kind = getattr(c, "pixel_filter_type", "BLACKMAN_HARRIS")
    if kind != "BLACKMAN_HARRIS":
        report.warn(f"Render settings: the {kind.replace('_', ' ').title()} pixel filter is "
                    "rendered as Blackman-Harris (of the same width)")
    if bscene.render.film_transparent and getattr(c, "film_transparent_glass", False):
        report.warn("Render settings: Transparent Glass is not rendered (glass stays opaque "
                    "in the film's alpha)")


def _rigid(matrix):
    m = np.array(matrix, dtype=np.float64)
    for k in range(3):
        n = np.linalg.norm(m[:3, k])
        if n > 0:
            m[:3, k] /= n
    return m


def camera_to_world(cam_obj):
    """The exported camera's to_world of cam_obj as it is now (motion blur's steps)."""
    return _rigid(cam_obj.matrix_world)


def view_window(half_fit, horizontal_fit, xaspect, yaspect, shift_x, shift_y):
    """Window [xmin, xmax, ymin, ymax] given the half extent of the fitted dimension."""
    if horizontal_fit:
        hx, hy = half_fit, half_fit * yaspect / xaspect
    else:
        hx, hy = half_fit * xaspect / yaspect, half_fit
    dx, dy = 2.0 * half_fit * shift_x, 2.0 * half_fit * shift_y
    return [-hx + dx, hx + dx, -hy + dy, hy + dy]


def camera_window(cam, film, pixel_aspect=(1.0, 1.0)):
    """View window and fit for Blender camera data `cam` on a film of the given size."""
    xaspect = film["width"] * pixel_aspect[0]
    yaspect = film["height"] * pixel_aspect[1]
    fit = cam.sensor_fit
    if fit == "AUTO":
        horizontal = xaspect >= yaspect
        sensor = cam.sensor_width
    elif fit == "HORIZONTAL":
        horizontal, sensor = True, cam.sensor_width
    else:
        horizontal, sensor = False, cam.sensor_height
    if cam.type == "ORTHO":
        half = 0.5 * cam.ortho_scale
    else:
        half = 0.5 * sensor / cam.lens
    return view_window(half, horizontal, xaspect, yaspect, cam.shift_x, cam.shift_y)


def export_camera(bscene, cam_obj, film, report):
    if cam_obj is None:
        report.warn("The scene has no camera: rendering from the origin, looking down -Z")
        return {"type": "perspective", "to_world": np.eye(4).tolist(),
                "screen": view_window(0.36, film["width"] >= film["height"], film["width"],
                                      film["height"], 0, 0), "clip": [0.1, 1000.0]}
    cam = cam_obj.data
    kind = "perspective"
    pano = {}
    if cam.type == "ORTHO":
        kind = "orthographic"
    elif cam.type == "PANO" and getattr(cam, "panorama_type", "") == "EQUIRECTANGULAR":
        kind = "equirectangular"
        pano = {"longitude": [float(cam.longitude_min), float(cam.longitude_max)],
                "latitude": [float(cam.latitude_min), float(cam.latitude_max)]}
    elif cam.type != "PERSP":
        sub = f" ({cam.panorama_type})" if cam.type == "PANO" else ""
        report.warn(f"Camera '{cam_obj.name}': {cam.type}{sub} cameras are not supported; "
                    "rendering a perspective camera")
    r = bscene.render
    screen = camera_window(cam, film, (r.pixel_aspect_x, r.pixel_aspect_y))
    out = {"type": kind, "to_world": _rigid(cam_obj.matrix_world).tolist(), "screen": screen,
           "clip": [float(cam.clip_start), float(cam.clip_end)], **pano}
    dof = export_dof(cam_obj, report)
    if dof is not None:
        out["dof"] = dof
    return out


def export_dof(cam_obj, report):
    """Blender's depth of field as Cycles reads it: lens radius = focal length / (2 f-stop)
    (f-stop at least 1e-5), focus distance along the view axis (to the focus object when set),
    blades, rotation and aperture ratio. None when off."""
    cam = cam_obj.data
    dof = cam.dof
    if not dof.use_dof:
        return None
    if cam.type != "PERSP":
        report.warn(f"Camera '{cam_obj.name}': depth of field on a {cam.type} camera is not "
                    "supported; rendered sharp")
        return None
    fstop = max(float(dof.aperture_fstop), 1e-5)
    focus = float(dof.focus_distance)
    target = dof.focus_object
    if target is not None:
        m = np.array(cam_obj.matrix_world, dtype=np.float64)
        axis = -m[:3, 2] / max(np.linalg.norm(m[:3, 2]), 1e-30)
        t = np.array(target.matrix_world, dtype=np.float64)[:3, 3]
        if getattr(dof, "focus_subtarget", ""):
            report.warn(f"Camera '{cam_obj.name}': the focus bone '{dof.focus_subtarget}' is "
                        f"ignored; focusing on the object '{target.name}'")
        focus = abs(float(np.dot(axis, t - m[:3, 3])))
    return {"radius": float(cam.lens) * 1e-3 / (2.0 * fstop), "focus_distance": focus,
            "blades": int(dof.aperture_blades), "rotation": float(dof.aperture_rotation),
            "ratio": float(dof.aperture_ratio)}


class ViewportView:
    """The 3D viewport as a camera: from the region's view and projection matrices."""

    def __init__(self, context, scale=1.0):
        region, rv3d = context.region, context.region_data
        self.width = max(1, int(region.width * scale))
        self.height = max(1, int(region.height * scale))
        self.view_matrix = np.array(rv3d.view_matrix, dtype=np.float64)
        self.window_matrix = np.array(rv3d.window_matrix, dtype=np.float64)
        self.is_perspective = bool(rv3d.is_perspective)
        self.filter_width = float(context.scene.render.filter_size)

    def key(self):
        return (self.width, self.height, self.view_matrix.tobytes(), self.window_matrix.tobytes())

    def film(self):
        return {"width": self.width, "height": self.height, "filter_width": self.filter_width}

    def camera(self):
        p = self.window_matrix
        to_world = _rigid(np.linalg.inv(self.view_matrix))
        if self.is_perspective:
            # (sx, sy, -1) projects to ndc x = p00*sx - p02, y = p11*sy - p12
            screen = [(-1 + p[0, 2]) / p[0, 0], (1 + p[0, 2]) / p[0, 0],
                      (-1 + p[1, 2]) / p[1, 1], (1 + p[1, 2]) / p[1, 1]]
            near = p[2, 3] / (p[2, 2] - 1.0)
            far = p[2, 3] / (p[2, 2] + 1.0)
            return {"type": "perspective", "to_world": to_world.tolist(), "screen": screen,
                    "clip": [float(abs(near)), float(abs(far))]}
        screen = [(-1 - p[0, 3]) / p[0, 0], (1 - p[0, 3]) / p[0, 0],
                  (-1 - p[1, 3]) / p[1, 1], (1 - p[1, 3]) / p[1, 1]]
        # ndc z = p22 * z + p23: the near and far planes as distances along the view axis
        d_near = (1 + p[2, 3]) / p[2, 2]
        d_far = -(1 - p[2, 3]) / p[2, 2]
        # orthographic viewports clip behind the view point too: start the rays there
        to_world[:3, 3] += to_world[:3, 2] * max(0.0, -d_near)
        return {"type": "orthographic", "to_world": to_world.tolist(), "screen": screen,
                "clip": [max(0.0, d_near), float(d_far - min(0.0, d_near))]}


__all__ = ["export_film", "film_unsupported", "export_camera", "export_dof", "camera_window", "view_window",
           "ViewportView"]
