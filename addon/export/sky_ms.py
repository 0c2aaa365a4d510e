"""The Multiple Scattering sky (Blender 5.0's default Sky Texture) in numpy: the radiance of a
spherical Earth's atmosphere seen from an altitude, and its sun disc.

The model is Fernando García Liñán's (2022, MIT licence; his Master's thesis and ShaderToy, a
spectral sky with four wavelength samples and a fitted multiple-scattering term, validated
against his path tracer https://github.com/fgarlin/skytracer; the spectral technique is
described at https://fgarlin.com/posts/2024-12-06-spectral_sky/), in the form Blender 5.0
evaluates it (intern/sky/source/sky_multiple_scattering.cpp, bpy 5.0.1; read, not copied). Its
structure follows Hillaire's "A Scalable and Production Ready Sky and Atmosphere Rendering
Technique" (EGSR 2020): a transmittance table, single scattering of the sun integrated along
the view ray with Hillaire's energy-conserving step ((S - S T_step) / sigma_t, from "Physically
Based Sky, Atmosphere and Cloud Rendering in Frostbite", 2016), plus a multiple-scattering
source term.

Constants, all García Liñán's model as Blender 5.0 states it (sky_multiple_scattering.cpp):
- geometry: Earth radius 6371 km, atmosphere 100 km thick; 64 march steps on every ray; a
  transmittance table of 256 (cos of the sun's zenith angle, linear in [-1, 1]) x 64 (altitude,
  linear in [0, 100 km]) entries, read bilinearly;
- the four wavelengths 630, 560, 490, 430 nm; the sun's spectral irradiance there
  (1.679, 1.828, 1.986, 1.307), "for an urban area";
- molecules (Rayleigh): sea-level scattering 6.605e-3, 1.067e-2, 1.842e-2, 3.156e-2 per km,
  falling with altitude h (km) as exp(-0.07771971 h^1.16364243) (his fit); phase
  3 / (16 pi) (1 + cos^2);
- ozone (the molecules' absorption): cross sections 3.472e-25, 3.914e-25, 1.349e-25, 1.103e-26
  (cm^2), times 334.5 (the mean Dobson of monthly means), times a log-normal number density
  3.78547397e20 exp(-5.5556 (ln h - 3.22261)^2 - ln h);
- aerosols: scattering cross sections 1.5908e-22, 1.7711e-22, 2.0942e-22, 2.4033e-22,
  absorption 2.8722e-24, 4.6168e-24, 7.9706e-24, 1.3578e-23, number density
  1.3681e20 (exp(-h / 0.73 km) + 2e6 / 1.3681e20) (a boundary layer over a background); phase
  Henyey-Greenstein with g = 0.8;
- multiple scattering at a point whose sun is at cos theta_s: an isotropic source
  0.02 (0.217, 0.347, 0.594, 1) / (1 + 5 exp(-17.92 cos theta_s)) (his fit of Earth's higher
  orders) plus the ground's second order: the ground (albedo 0.3, Lambertian, a constant of
  the model: the node's Ground Albedo is Hosek / Wilkie's) seen under the planet's solid angle
  from the point, lit by the sun through the table, times cos theta_s;
- spectral -> CIE XYZ: the model's 4 x 3 matrix (rows 630 ... 430 nm); XYZ -> linear Rec.709
  (D65) as the other sky types here; negative RGB is clamped to 0 (Cycles' xyz_to_rgb_clamped).

Cycles (kernel/svm/sky.h, scene/shader_nodes.cpp, scene/image_sky.cpp) tabulates the sky in a
512 x 256 image, elevation warped as sign(l) l^2 pi/2 (more rows at the horizon), azimuth from
the sun, read bilinearly; the same table geometry is used here for the elevation. The phase
functions, which alone carry the sharp aerosol peak round the sun, are taken out of the march
(they depend on the view and sun directions only) and applied per texel; what the march leaves
is smooth in azimuth and is tabulated at 33 azimuths from the sun. Sun elevation and rotation
are Blender's: the sun towards (cos e sin r, cos e cos r, sin e); altitude is clamped to
[1 m, 99.999 km] as Cycles does.

The sun disc (angular diameter = Sun Size, at least 0.0005 rad as in Cycles) has radiance
E_sun T(sun) / Omega, interpolated between the disc's bottom and top edges, times limb
darkening 1 - 0.6 (1 - sqrt(1 - (r / R)^2)) (mean 0.8 over the disc) and Sun Intensity; it is
hidden below the planet's horizon seen from the altitude. `sun_light` returns it as a sun lamp
of the disc's angle and irradiance."""

import functools
import math

import numpy as np

EARTH_R = 6371.0                 # km
ATMOS_H = 100.0                  # km
ATMOS_R = EARTH_R + ATMOS_H
STEPS = 64                       # march steps (transmittance and in-scattering)
T_RES_COS, T_RES_ALT = 256, 64   # transmittance table
SKY_ROWS = 256                   # elevation rows of the sky table (Cycles' image height)
SKY_AZIMUTHS = 33                # azimuths from the anti-sun (0) to the sun (pi)
G = 0.8                          # aerosol Henyey-Greenstein anisotropy
GROUND_ALBEDO = 0.3
MIN_SUN_SIZE = 0.0005            # rad, Cycles' SkyTextureNode::get_sun_size

SUN_IRRADIANCE = np.array([1.679, 1.828, 1.986, 1.307])
MOLECULAR_SCATTERING = np.array([6.605e-3, 1.067e-2, 1.842e-2, 3.156e-2])
OZONE_CROSS_SECTION = np.array([3.472e-25, 3.914e-25, 1.349e-25, 11.03e-27])
OZONE_MEAN_DOBSON = 334.5
AEROSOL_ABSORPTION = np.array([2.8722e-24, 4.6168e-24, 7.9706e-24, 1.3578e-23])
AEROSOL_SCATTERING = np.array([1.5908e-22, 1.7711e-22, 2.0942e-22, 2.4033e-22])
AEROSOL_BASE_DENSITY = 1.3681e20
AEROSOL_BACKGROUND_DENSITY = 2e6
AEROSOL_HEIGHT_SCALE = 0.73      # km
MS_FIT = 0.02 * np.array([0.217, 0.347, 0.594, 1.0])
SPECTRAL_XYZ = np.array([[53.386917738564668, 22.981337506691025, 0.0],
                         [43.904844466369358, 71.347795700053394, 0.102506867965741],
                         [1.6137278251608962, 18.422960591455485, 31.742921188390806],
                         [20.762668673810577, 2.3614213523314369, 110.48009643252140]])


def _profiles(h):
    """(..., 3) altitude profiles (h in km) of aerosol number density, molecular scattering
    relative to sea level, and ozone column density (Dobson-weighted)."""
    aer = AEROSOL_BASE_DENSITY * (np.exp(-h / AEROSOL_HEIGHT_SCALE) +
                                  AEROSOL_BACKGROUND_DENSITY / AEROSOL_BASE_DENSITY)
    mol = np.exp(-0.07771971 * np.power(h, 1.16364243))
    log_h = np.log(np.maximum(h, 1e-4))
    ozone = 3.78547397e20 * np.exp(-(log_h - 3.22261) ** 2 * 5.55555555 - log_h) * \
        OZONE_MEAN_DOBSON
    return np.stack([aer, mol, ozone], axis=-1)


class Atmosphere:
    """One atmosphere (air, aerosol and ozone density factors): its transmittance table and
    the spectra its profiles make."""

    def __init__(self, air, aerosol, ozone):
        air, aerosol, ozone = (max(float(v), 0.0) for v in (air, aerosol, ozone))
        # profile (3) -> extinction (4); profile -> molecular / aerosol scattering (4)
        self.ext = np.stack([(AEROSOL_ABSORPTION + AEROSOL_SCATTERING) * aerosol,
                             MOLECULAR_SCATTERING * air, OZONE_CROSS_SECTION * ozone])
        self.sca_m = MOLECULAR_SCATTERING * air
        self.sca_a = AEROSOL_SCATTERING * aerosol
        cos = np.linspace(-1.0, 1.0, T_RES_COS)
        alt_n = np.linspace(0.0, 1.0, T_RES_ALT)
        self.table = self.transmittance(cos[None, :], alt_n[:, None])  # (alt, cos, 4)
        self.flat = np.ascontiguousarray(self.table.reshape(-1, 4), np.float32)

    def transmittance(self, cos, alt_n):
        """Transmittance to the top of the atmosphere from altitude alt_n * 100 km towards a
        direction at cos of the zenith angle (the planet does not occlude, as in Blender)."""
        cos, alt_n = np.broadcast_arrays(np.asarray(cos, np.float64),
                                         np.asarray(alt_n, np.float64))
        r0 = EARTH_R + alt_n * ATMOS_H
        b = r0 * cos
        t_d = -b + np.sqrt(np.maximum(b * b - r0 * r0 + ATMOS_R * ATMOS_R, 0.0))
        dt = t_d / STEPS
        t = (np.arange(STEPS) + 0.5) * dt[..., None]
        r = np.sqrt(r0[..., None] ** 2 + 2.0 * b[..., None] * t + t * t)
        depth = _profiles(np.maximum(r - EARTH_R, 0.0)).sum(axis=-2) * dt[..., None]
        return np.exp(-(depth @ self.ext))

    def lookup(self, cos, alt_n):
        """The table read bilinearly (clamped), as Blender reads it: (..., 4), float32 (as
        Blender's)."""
        x = (np.clip(cos * 0.5 + 0.5, 0.0, 1.0) * (T_RES_COS - 1)).astype(np.float32)
        y = (np.clip(alt_n, 0.0, 1.0) * (T_RES_ALT - 1)).astype(np.float32)
        x1, y1 = x.astype(np.int32), y.astype(np.int32)
        fx, fy = (x - x1)[..., None], (y - y1)[..., None]
        dx = (x1 < T_RES_COS - 1).astype(np.int32)
        dy = (y1 < T_RES_ALT - 1).astype(np.int32) * T_RES_COS
        i = y1 * T_RES_COS + x1
        flat = self.flat
        c11, c12 = flat[i], flat[i + dx]
        c21, c22 = flat[i + dy], flat[i + dy + dx]
        bottom = c11 + fx * (c12 - c11)
        top = c21 + fx * (c22 - c21)
        return bottom + fy * (top - bottom)

    def ground_term(self, cos_s):
        """Transmittance from the sun to the ground at cos of the sun's zenith angle (the
        table's first row, read linearly): (..., 4)."""
        x = np.clip(cos_s * 0.5 + 0.5, 0.0, 1.0) * (T_RES_COS - 1)
        x1 = x.astype(np.int64)
        x2 = np.minimum(x1 + 1, T_RES_COS - 1)
        row = self.table[0]
        return row[x1] + (x - x1)[..., None] * (row[x2] - row[x1])

    def multiple_scattering(self, cos_s, alt_n, r):
        """The isotropic source of higher orders at points (rows, az, steps) whose altitude
        alt_n and radius r (rows, 1, steps) do not depend on the azimuth: (..., 4), the fit
        plus the ground's second order."""
        omega = 2.0 * math.pi * (1.0 - np.sqrt(np.maximum(1.0 - (EARTH_R / r) ** 2, 0.0)))
        top = np.ones_like(alt_n)
        ground_to_sample = self.lookup(top, np.zeros_like(alt_n)) / \
            np.maximum(self.lookup(top, alt_n), 1e-30)
        ground = (omega[..., None] * (GROUND_ALBEDO / (4.0 * math.pi ** 2)) *
                  ground_to_sample) * self.ground_term(cos_s) * cos_s[..., None]
        fit = MS_FIT / (1.0 + 5.0 * np.exp(-17.92 * cos_s))[..., None]
        return fit + ground


def sky_rows():
    """Elevations (rad) of the sky table's rows: sign(l) l^2 pi/2 at the row centres."""
    l = (np.arange(SKY_ROWS) + 0.5) / SKY_ROWS * 2.0 - 1.0
    return np.copysign(l * l, l) * (0.5 * math.pi)


def march(atm, sun_elevation, altitude_km):
    """Per (row, azimuth) the view-ray integrals (3, rows, azimuths, 4): molecular and aerosol
    single scattering without their phase functions, and the multiple-scattering term. The
    camera at the altitude, the sun at azimuth pi; azimuth a from 0 to pi."""
    elev = sky_rows()
    a = np.linspace(0.0, math.pi, SKY_AZIMUTHS)
    ce, se = np.cos(elev), np.sin(elev)
    r0 = EARTH_R + altitude_km
    b = r0 * se                                        # ray . origin
    atmos = -b + np.sqrt(b * b - r0 * r0 + ATMOS_R * ATMOS_R)
    disc = b * b - (r0 * r0 - EARTH_R * EARTH_R)
    ground = np.where((b < 0.0) & (disc >= 0.0), -b - np.sqrt(np.maximum(disc, 0.0)), -1.0)
    t_d = np.where(ground >= 0.0, ground, atmos)
    dt = t_d / STEPS                                    # (rows,)
    t = (np.arange(STEPS) + 0.5)[None, :] * dt[:, None]  # (rows, steps)
    z = r0 + t * se[:, None]
    horiz = t * ce[:, None]
    r = np.sqrt(horiz * horiz + z * z)
    alt = np.maximum(r - EARTH_R, 0.0)
    alt_n = alt / ATMOS_H
    prof = _profiles(alt)                               # (rows, steps, 3)
    ext = prof @ atm.ext                                # (rows, steps, 4)
    depth = dt[:, None, None] * ext
    step_t = np.exp(-depth)
    before = np.exp(-(np.cumsum(depth, axis=1) - depth))    # transmittance to the step
    w = before * (1.0 - step_t) / np.maximum(ext, 1e-7)
    sm = prof[..., 1:2] * atm.sca_m
    sa = prof[..., 0:1] * atm.sca_a
    cos_t, sin_t = math.sin(sun_elevation), abs(math.cos(sun_elevation))
    # cos of the sun's zenith angle at each sample: the local zenith is the sample's position
    cos_s = ((-horiz / r)[:, None, :] * (np.cos(a)[None, :, None] * sin_t) +
             (z / r * cos_t)[:, None, :])               # (rows, az, steps)
    t_sun = atm.lookup(cos_s, np.broadcast_to(alt_n[:, None, :], cos_s.shape))
    ms = atm.multiple_scattering(cos_s, alt_n[:, None, :], r[:, None, :])
    wb = w[:, None]
    i_m = np.einsum("rask,rsk->rak", t_sun, w * sm)
    i_a = np.einsum("rask,rsk->rak", t_sun, w * sa)
    i_ms = (wb * (sm + sa)[:, None] * ms).sum(axis=2)
    return np.stack([i_m, i_a, i_ms])


def _phases(cos_theta):
    """Molecular (Rayleigh) and aerosol (Henyey-Greenstein) phase functions; cos_theta is the
    cosine between the reversed view ray and the sun."""
    p_m = 3.0 / (16.0 * math.pi) * (1.0 + cos_theta * cos_theta)
    den = 1.0 + G * G + 2.0 * G * cos_theta
    p_a = (1.0 - G * G) / (4.0 * math.pi * den * np.sqrt(den))
    return p_m, p_a


def _interp_table(tab, elev, az):
    """The march's table (3, rows, azimuths, 4) at elevations / azimuths (...): rows by
    Cycles' inverse warp, bilinear, clamped."""
    y = np.sqrt(np.abs(elev) / (0.5 * math.pi)) * np.sign(elev) * 0.5 + 0.5
    y = np.clip(y * SKY_ROWS - 0.5, 0.0, SKY_ROWS - 1.0)
    x = np.clip(az / math.pi * (SKY_AZIMUTHS - 1), 0.0, SKY_AZIMUTHS - 1.0)
    y1, x1 = y.astype(np.int64), x.astype(np.int64)
    y2, x2 = np.minimum(y1 + 1, SKY_ROWS - 1), np.minimum(x1 + 1, SKY_AZIMUTHS - 1)
    fy, fx = (y - y1)[..., None], (x - x1)[..., None]
    lo = tab[:, y1, x1] + fx * (tab[:, y1, x2] - tab[:, y1, x1])
    hi = tab[:, y2, x1] + fx * (tab[:, y2, x2] - tab[:, y2, x1])
    return lo + fy * (hi - lo)


def sun_vector(sun_elevation, sun_rotation):
    """Blender's sun direction for the Nishita-family sky types (z up)."""
    ce = math.cos(sun_elevation)
    return np.array([ce * math.sin(sun_rotation), ce * math.cos(sun_rotation),
                     math.sin(sun_elevation)])


def _clamp_altitude(altitude_m):
    a = float(altitude_m) if math.isfinite(float(altitude_m)) else 1.0
    return min(max(a, 1.0), 99999.0) / 1000.0


def xyz_to_rgb(xyz, matrix):
    return np.maximum(xyz @ matrix.T, 0.0)


def sky_table(sun_elevation, sun_rotation, altitude, air, aerosol, ozone):
    """One sky's march (march()) with its sun: what sky_radiance reads, for many directions."""
    s = sun_vector(sun_elevation, sun_rotation)
    elev_s = math.asin(float(np.clip(s[2], -1.0, 1.0)))
    atm = _atmosphere(float(air), float(aerosol), float(ozone))
    # azimuths from the sun's side; any reference serves a sun at the zenith
    hs = np.array([s[0], s[1]]) if math.hypot(s[0], s[1]) > 1e-9 else \
        np.array([math.sin(sun_rotation), math.cos(sun_rotation)])
    return march(atm, elev_s, _clamp_altitude(altitude)), s, hs


def table_radiance(table, dirs, matrix):
    """Linear RGB (..., 3) of a sky_table for unit directions `dirs` (..., 3), z up; `matrix`
    XYZ -> RGB."""
    tab, s, hs = table
    d = np.asarray(dirs, np.float64)
    elev = np.arcsin(np.clip(d[..., 2], -1.0, 1.0))
    dot = d[..., 0] * hs[0] + d[..., 1] * hs[1]
    cross = d[..., 0] * hs[1] - d[..., 1] * hs[0]
    az = math.pi - np.arctan2(np.abs(cross), dot)     # the table's azimuth: the sun at pi
    i_m, i_a, i_ms = _interp_table(tab, elev, az)
    p_m, p_a = _phases(-(d @ s))
    spectrum = SUN_IRRADIANCE * (p_m[..., None] * i_m + p_a[..., None] * i_a + i_ms)
    rgb = xyz_to_rgb(spectrum @ SPECTRAL_XYZ, matrix)
    return np.where(np.isfinite(rgb), rgb, 0.0)


def table_grid(table, elev, phi, matrix):
    """Linear RGB (rows, columns, 3) of a sky_table on a grid of directions (cos e cos phi,
    cos e sin phi, sin e), elevations `elev` (rows) by azimuths `phi` (columns): table_radiance
    made separable (the table read per row in elevation, then per column in azimuth; spectra
    folded into RGB before the per-texel phase functions), float32."""
    tab, s, hs = table
    elev, phi = np.asarray(elev, np.float64), np.asarray(phi, np.float64)
    y = np.sqrt(np.abs(elev) / (0.5 * math.pi)) * np.sign(elev) * 0.5 + 0.5
    y = np.clip(y * SKY_ROWS - 0.5, 0.0, SKY_ROWS - 1.0)
    y1 = y.astype(np.int64)
    y2, fy = np.minimum(y1 + 1, SKY_ROWS - 1), (y - y1)[None, :, None, None]
    rows = tab[:, y1] + fy * (tab[:, y2] - tab[:, y1])                 # (3, rows, az, 4)
    to_rgb = (SUN_IRRADIANCE[:, None] * SPECTRAL_XYZ) @ np.asarray(matrix).T   # (4, 3)
    rows = (rows @ to_rgb).astype(np.float32)                          # (3, rows, az, 3)
    cp, sp = np.cos(phi), np.sin(phi)
    az = math.pi - np.arctan2(np.abs(cp * hs[1] - sp * hs[0]), cp * hs[0] + sp * hs[1])
    x = np.clip(az / math.pi * (SKY_AZIMUTHS - 1), 0.0, SKY_AZIMUTHS - 1.0)
    x1 = x.astype(np.int64)
    x2, fx = np.minimum(x1 + 1, SKY_AZIMUTHS - 1), (x - x1).astype(np.float32)[:, None]
    j = rows[:, :, x1] + fx * (rows[:, :, x2] - rows[:, :, x1])        # (3, rows, cols, 3)
    cos_view = -(np.cos(elev)[:, None] * (cp * s[0] + sp * s[1])[None, :] +
                 (np.sin(elev) * s[2])[:, None])
    p_m, p_a = (p.astype(np.float32)[..., None] for p in _phases(cos_view))
    rgb = np.maximum(p_m * j[0] + p_a * j[1] + j[2], 0.0)
    return np.where(np.isfinite(rgb), rgb, np.float32(0.0))


def sky_radiance(dirs, sun_elevation, sun_rotation, altitude, air, aerosol, ozone, matrix):
    """Linear RGB (..., 3) of the sky (no sun disc) for unit directions `dirs` (..., 3), z up;
    `matrix` XYZ -> RGB."""
    return table_radiance(sky_table(sun_elevation, sun_rotation, altitude, air, aerosol, ozone),
                          dirs, matrix)


@functools.lru_cache(maxsize=4)
def _atmosphere(air, aerosol, ozone):
    return Atmosphere(air, aerosol, ozone)


def earth_dip(altitude):
    """How far below the horizon (rad) the planet's edge lies from the altitude."""
    return 0.5 * math.pi - math.asin(EARTH_R / (EARTH_R + _clamp_altitude(altitude)))


def sun_light(sun_elevation, sun_rotation, sun_size, sun_intensity, altitude, air, aerosol,
              ozone, matrix):
    """The sun disc as (unit direction towards the sun, angular diameter, RGB irradiance on a
    surface facing it), or None when the planet hides it. The disc's mean radiance (the
    edge-to-edge interpolation is linear, so its mean is the centre's; limb darkening's mean
    is 0.8) times its solid angle: E_sun T 0.8, T the mean of the edges' transmittances."""
    s = sun_vector(sun_elevation, sun_rotation)
    elev = math.asin(float(np.clip(s[2], -1.0, 1.0)))
    size = max(float(sun_size), MIN_SUN_SIZE)
    if elev <= -earth_dip(altitude):
        return None
    atm = _atmosphere(float(air), float(aerosol), float(ozone))
    alt_n = _clamp_altitude(altitude) / ATMOS_H
    edges = np.sin(np.array([elev - 0.5 * size, elev + 0.5 * size]))  # cos of zenith angles
    t = atm.transmittance(edges, np.full(2, alt_n)).mean(axis=0)
    rgb = xyz_to_rgb((SUN_IRRADIANCE * t) @ SPECTRAL_XYZ, matrix)
    return s, size, 0.8 * rgb * max(float(sun_intensity), 0.0)
