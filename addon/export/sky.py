"""Sky Texture -> an equirectangular radiance map, evaluated at export (numpy), that the core
then importance-samples like any environment map (docs/scene_format.md, "World").

Preetham is written from the published model: A. J. Preetham, P. Shirley, B. Smits, "A
Practical Analytic Model for Daylight", SIGGRAPH 1999 (Perez et al.'s all-weather luminance
distribution, its coefficients linear in turbidity T, Appendix A.2; the zenith luminance and
chromaticities of Appendix A.3). Luminance and chromaticity x, y are each the zenith value times
F(theta, gamma) / F(0, theta_sun), converted xyY -> XYZ -> linear Rec.709 (D65). Blender's
conventions, measured against Cycles (bpy 5.0.1; the world_sky blend scene in
tests/render/test_cycles_compare.py): the result is scaled by 0.06 (Y in kcd/m^2 to Blender's
radiance units), below the horizon the gradation term takes its horizon limit (1), and Preetham
has no sun disc.

Multiple Scattering (Blender 5.0's default) is García Liñán's model as Blender 5.0 evaluates
it, written in numpy in sky_ms.py (its sources and constants are cited there): the map
(1024 x 512, texels near the horizon averaged over their elevation; 0.3 s CPU per sky,
bench/sky_export.py) matches Cycles' sky within 0.5 % at every direction, 0.03 % in the median
(tests/render/test_sky_cycles.py renders it through a panoramic camera), and the stage it
lights within 0.1 % (world_sky_ms, tests/render/test_cycles_compare.py).
Its sun disc, a fraction of a texel in the map, is not drawn into the map: it becomes a sun
light of the world (world["sun"], docs/scene_format.md) with the disc's angle and irradiance,
which lights the scene, shadows and reflections as the disc does and, as the world's own light
(python/lantern/scene.py to_native), is drawn for camera rays where the world is (a Blender sun
lamp never is) and follows the world's ray visibility; tests/render/test_sky_cycles.py compares
the disc the camera sees with Cycles' (the lt integrator, Python API only, draws neither the
world nor the disc for the camera: the core warns). Inside the disc the map's sky stays under
it, where Cycles draws the disc alone (the sky there is 2e-5 to 4e-5 of the disc's radiance at
Blender's defaults, 1e-3 with test_sky_cycles.py's wide dim disc; sky_ms.sky_radiance). Sun
Intensity scales the disc alone, as in Cycles; Ground Albedo belongs to Hosek / Wilkie (the
model's ground albedo is its own constant 0.3).

A Mapping on the Vector turns the sky (map and sun) as Cycles 5.0.1 does (measured in
tests/render/test_sky_cycles.py): Preetham's always; Multiple Scattering's only with the Sun
Disc off, since with it on Blender holds the Vector unavailable and Cycles ignores the link
(world.vector_matrix names it).

Single Scattering (the former Nishita: 21 wavelengths, one scattering) is Cycles' own table of
it, built and read as Cycles does in sky_ss.py (within 4.3e-4 of Cycles at every direction,
tests/render/test_sky_cycles.py; 0.5-0.7 s CPU per sky, bench/sky_export.py), sampled into
a 1024 x 512 map (texels within HORIZON_BAND of the horizon averaged over their elevation),
its disc a sun light as above (within 0.1 % of Cycles' irradiance). Hosek / Wilkie (its data
set is large) is not rendered: a warning names it, and the Background's own colour lights the
scene instead."""

import functools
import math

import numpy as np

from . import sky_ms, sky_ss

SCALE = 0.06            # Preetham's Y (kcd/m^2) -> Blender radiance (measured, see above)
MAP_SIZE = (512, 256)   # width, height: a smooth sky needs no more
# Multiple Scattering: its horizon is sharp (Cycles' table has rows of 0.001 degrees there), so
# a finer map, whose texels from HORIZON_BAND below the planet's edge (below the horizon by
# the dip of the altitude) to HORIZON_BAND above the horizon hold their mean over
# HORIZON_SUBROWS elevations (point values elsewhere): in world_sky_ms the horizon's blocks
# were 1 % off Cycles with 512 x 256 point texels, 0.25 % with 1024 x 512, within 0.1 % with
# the band averaged
MS_MAP_SIZE = (1024, 512)
HORIZON_BAND = math.radians(4.0)
HORIZON_SUBROWS = 8

# Perez coefficients (A..E) = a * T + b, for Y, x, y (Preetham et al. 1999, A.2)
_PEREZ = {
    "Y": ((0.1787, -1.4630), (-0.3554, 0.4275), (-0.0227, 5.3251), (0.1206, -2.5771),
          (-0.0670, 0.3703)),
    "x": ((-0.0193, -0.2592), (-0.0665, 0.0008), (-0.0004, 0.2125), (-0.0641, -0.8989),
          (-0.0033, 0.0452)),
    "y": ((-0.0167, -0.2608), (-0.0950, 0.0092), (-0.0079, 0.2102), (-0.0441, -1.6537),
          (-0.0109, 0.0529)),
}
# zenith chromaticity = [T^2, T, 1] M [theta_s^3, theta_s^2, theta_s, 1] (A.3)
_ZENITH_X = np.array([[0.00166, -0.00375, 0.00209, 0.0],
                      [-0.02903, 0.06377, -0.03202, 0.00394],
                      [0.11693, -0.21196, 0.06052, 0.25886]])
_ZENITH_Y = np.array([[0.00275, -0.00610, 0.00317, 0.0],
                      [-0.04214, 0.08970, -0.04153, 0.00516],
                      [0.15346, -0.26756, 0.06670, 0.26688]])
# CIE XYZ -> linear Rec.709 (D65), Blender's scene-linear space
_XYZ_TO_REC709 = np.array([[3.2404542, -1.5371385, -0.4985314],
                           [-0.9692660, 1.8760108, 0.0415560],
                           [0.0556434, -0.2040259, 1.0572252]])


def _perez(coeffs, cos_theta, gamma):
    """Perez's F(theta, gamma); below the horizon (cos_theta <= 0) its gradation term is 1."""
    a, b, c, d, e = coeffs
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        grad = np.where(cos_theta > 1e-6, 1.0 + a * np.exp(b / np.maximum(cos_theta, 1e-6)),
                        1.0)
    return grad * (1.0 + c * np.exp(d * gamma) + e * np.cos(gamma) ** 2)


def preetham_radiance(dirs, sun_dir, turbidity):
    """Linear Rec.709 radiance (..., 3) of the Preetham sky for unit directions `dirs` (..., 3),
    z up, the sun towards `sun_dir`."""
    t = float(np.clip(turbidity, 1.0, 30.0))
    s = np.asarray(sun_dir, np.float64)
    s = s / max(np.linalg.norm(s), 1e-12)
    theta_s = math.acos(float(np.clip(s[2], -1.0, 1.0)))
    chi = (4.0 / 9.0 - t / 120.0) * (math.pi - 2.0 * theta_s)
    zenith = {"Y": (4.0453 * t - 4.9710) * math.tan(chi) - 0.2155 * t + 2.4192}
    tt = np.array([t * t, t, 1.0])
    ts = np.array([theta_s ** 3, theta_s ** 2, theta_s, 1.0])
    zenith["x"], zenith["y"] = tt @ _ZENITH_X @ ts, tt @ _ZENITH_Y @ ts
    cos_theta = dirs[..., 2]
    gamma = np.arccos(np.clip(dirs @ s, -1.0, 1.0))
    val = {}
    for k, rows in _PEREZ.items():
        coeffs = [a * t + b for a, b in rows]
        val[k] = zenith[k] * _perez(coeffs, cos_theta, gamma) / \
            _perez(coeffs, np.float64(1.0), np.float64(theta_s))
    x, y, big_y = val["x"], val["y"], val["Y"]
    y = np.where(np.abs(y) > 1e-9, y, 1e-9)
    xyz = np.stack([x / y * big_y, big_y, (1.0 - x - y) / y * big_y], axis=-1)
    rgb = xyz @ _XYZ_TO_REC709.T * SCALE
    return np.where(np.isfinite(rgb), rgb, 0.0)


def equirect_directions(width, height):
    """Unit directions (height, width, 3) of the texel centres of an equirectangular map as
    scene/envmap.h reads it (rows bottom to top; u = 0.5 - atan2(y, x) / 2 pi)."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    phi = (0.5 - u) * 2.0 * math.pi
    elev = (v - 0.5) * math.pi
    ce = np.cos(elev)[:, None]
    return np.stack([ce * np.cos(phi)[None, :], ce * np.sin(phi)[None, :],
                     np.broadcast_to(np.sin(elev)[:, None], (height, width))], axis=-1)


_LABELS = {"MULTIPLE_SCATTERING": "Multiple Scattering", "SINGLE_SCATTERING": "Single Scattering",
           "HOSEK_WILKIE": "Hosek / Wilkie", "NISHITA": "Nishita"}


def _check_mapping(node, where, report):
    tm = getattr(node, "texture_mapping", None)
    if tm is not None and (any(abs(v) > 1e-6 for v in tm.rotation) or
                           any(abs(v - 1.0) > 1e-6 for v in tm.scale)):
        report.warn(f"{where}: Sky Texture '{node.name}': its own texture mapping is ignored "
                    "(use a Mapping node)")


def _finite(node, name, default, lo=None, hi=None):
    v = float(getattr(node, name, default))
    if not math.isfinite(v):
        v = default
    if lo is not None:
        v = max(v, lo)
    if hi is not None:
        v = min(v, hi)
    return v


def _ms_params(node):
    """The Multiple Scattering node's settings, made finite and in range."""
    return (_finite(node, "sun_elevation", math.radians(15.0)),
            _finite(node, "sun_rotation", 0.0),
            _finite(node, "altitude", 100.0, 0.0, 100000.0),
            _finite(node, "air_density", 1.0, 0.0, 1000.0),
            _finite(node, "aerosol_density", 1.0, 0.0, 1000.0),
            _finite(node, "ozone_density", 1.0, 0.0, 1000.0))


def sky_map(node, where, report):
    """The Sky Texture node's radiance as an equirectangular float32 map (H, W, 3), rows bottom
    to top (no sun disc: see sky_sun); None (with a warning) for a sky type Lantern does not
    render."""
    kind = getattr(node, "sky_type", "")
    if kind not in ("PREETHAM", "MULTIPLE_SCATTERING", "SINGLE_SCATTERING"):
        report.warn(f"{where}: Sky Texture '{node.name}' of type {_LABELS.get(kind, kind)} is "
                    "not rendered (Preetham, Single and Multiple Scattering are); the "
                    "Background's own colour is used")
        return None
    _check_mapping(node, where, report)
    if kind == "PREETHAM":
        return _preetham_map(tuple(float(v) for v in node.sun_direction),
                             float(node.turbidity))
    if kind == "SINGLE_SCATTERING":
        return _single_scattering_map(_ms_params(node))
    return _multiple_scattering_map(_ms_params(node))


@functools.lru_cache(maxsize=4)
def _preetham_map(sun_dir, turbidity):
    """The map of one sky (0.1 s): kept across viewport exports; read-only."""
    w, h = MAP_SIZE
    rgb = np.ascontiguousarray(np.maximum(preetham_radiance(equirect_directions(w, h), sun_dir,
                                                            turbidity), 0.0), np.float32)
    rgb.setflags(write=False)
    return rgb


def horizon_band(elev, altitude):
    """Which elevations (rad) lie in the averaged band: the horizon and the planet's edge."""
    return (elev < HORIZON_BAND) & (elev > -sky_ms.earth_dip(altitude) - HORIZON_BAND)


@functools.lru_cache(maxsize=4)
def _multiple_scattering_map(params):
    """The Multiple Scattering map of one sky (sky_ms.py; 0.5 s): kept, read-only."""
    w, h = MS_MAP_SIZE
    table = sky_ms.sky_table(*params)
    elev = ((np.arange(h) + 0.5) / h - 0.5) * math.pi        # equirect_directions' texels
    phi = (0.5 - (np.arange(w) + 0.5) / w) * 2.0 * math.pi
    rgb = sky_ms.table_grid(table, elev, phi, _XYZ_TO_REC709)
    rows = np.nonzero(horizon_band(elev, params[2]))[0]
    if len(rows):
        sub = ((np.arange(HORIZON_SUBROWS) + 0.5) / HORIZON_SUBROWS - 0.5) * (math.pi / h)
        e = (elev[rows][:, None] + sub[None, :]).ravel()
        band = sky_ms.table_grid(table, e, phi, _XYZ_TO_REC709)
        rgb[rows] = band.reshape(len(rows), HORIZON_SUBROWS, w, 3).mean(axis=1)
    rgb = np.ascontiguousarray(rgb, np.float32)
    rgb.setflags(write=False)
    return rgb


def ss_table(params):
    """The Single Scattering table (sky_ss.py) of _ms_params: the sun's rotation is the
    lookup's, not the table's."""
    elev, _, alt, air, aerosol, ozone = params
    return sky_ss.sky_table(elev, alt, air, aerosol, ozone)


@functools.lru_cache(maxsize=4)
def _single_scattering_map(params):
    """The Single Scattering map of one sky (sky_ss.py; 0.6 s CPU, bench/sky_export.py):
    Cycles' table read at the texels (means over HORIZON_SUBROWS elevations within
    HORIZON_BAND of the horizon, where the table's rows are dense); kept, read-only."""
    w, h = MS_MAP_SIZE
    table = ss_table(params)
    dirs = equirect_directions(w, h)
    rgb = sky_ss.table_radiance(table, dirs, params[1], _XYZ_TO_REC709)
    elev = ((np.arange(h) + 0.5) / h - 0.5) * math.pi
    rows = np.nonzero(np.abs(elev) < HORIZON_BAND)[0]
    if len(rows):
        sub = ((np.arange(HORIZON_SUBROWS) + 0.5) / HORIZON_SUBROWS - 0.5) * (math.pi / h)
        e = elev[rows][:, None] + sub[None, :]                       # (rows, sub)
        az = dirs[rows[0], :, :2] / np.linalg.norm(dirs[rows[0], :, :2], axis=-1)[..., None]
        d = np.concatenate([np.cos(e)[..., None, None] * az[None, None],
                            np.broadcast_to(np.sin(e)[..., None, None],
                                            e.shape + (w, 1))], axis=-1)
        band = sky_ss.table_radiance(table, d, params[1], _XYZ_TO_REC709)
        rgb[rows] = band.mean(axis=1)
    rgb = np.ascontiguousarray(rgb, np.float32)
    rgb.setflags(write=False)
    return rgb


def sky_sun(node, strength, to_map, where, report):
    """The Multiple Scattering sky's sun disc as a sun light (docs/scene_format.md, "World"):
    the disc's angle, its irradiance times the Background strength, towards the world
    direction the texture's vector maps onto the sun; None without a disc (Sun Disc off, the
    sun below the planet's horizon, or a black disc)."""
    kind = getattr(node, "sky_type", "")
    if kind not in ("MULTIPLE_SCATTERING", "SINGLE_SCATTERING") or not bool(node.sun_disc):
        return None
    elev, rot, alt, air, aerosol, ozone = _ms_params(node)
    size = _finite(node, "sun_size", 0.009512, 0.0, math.pi / 2)
    intensity = _finite(node, "sun_intensity", 1.0, 0.0, 1000.0)
    if kind == "SINGLE_SCATTERING":
        disc = sky_ss.sun_light(elev, size, intensity, alt, air, aerosol, _XYZ_TO_REC709)
        sun = None if disc is None else (sky_ms.sun_vector(elev, rot),) + disc
    else:
        sun = sky_ms.sun_light(elev, rot, size, intensity, alt, air, aerosol, ozone,
                               _XYZ_TO_REC709)
    if sun is None:
        return None
    towards, angle, irradiance = sun
    m = np.asarray(to_map, np.float64)
    try:  # to_map takes a world direction to the texture's vector: invert it for the sun
        d = np.linalg.solve(m, towards)
    except np.linalg.LinAlgError:
        d = None
    if d is None or not np.all(np.isfinite(d)) or np.linalg.norm(d) < 1e-12:
        report.warn(f"{where}: Sky Texture '{node.name}': the sun disc is dropped (the "
                    "texture's mapping is singular)")
        return None
    d = d / np.linalg.norm(d)
    power = [float(c) * strength for c in irradiance]
    if max(power) <= 0.0 or not all(math.isfinite(c) for c in power):
        return None
    return {"type": "sun", "name": f"sky:{node.name}", "direction": (-d).tolist(),
            "angle": angle, "strength": power}


def sky_world(node, out, color, strength, to_map, where, report):
    """`out` (the world dict) with the sky's map (and sun), or the Background colour when the
    sky type is not rendered."""
    rgb = sky_map(node, where, report)
    if rgb is None:
        out["color"] = [c * strength for c in color]
        return out
    out.update({"map": rgb, "map_name": f"sky:{node.name}", "strength": [strength] * 3,
                "projection": "equirectangular", "to_map": np.asarray(to_map).tolist()})
    sun = sky_sun(node, strength, to_map, where, report)
    if sun is not None:   # the world's: its ray visibility applies (scene.py to_native)
        out["sun"] = sun
    return out
