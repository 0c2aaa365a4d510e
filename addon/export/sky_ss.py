"""The Single Scattering sky (Blender 5.0's name for the former Nishita Sky Texture) in numpy:
the sun's light scattered once by the air and the aerosols of a spherical Earth, seen from an
altitude, and its sun disc.

The model is Nishita et al.'s ("Display of the Earth Taking into Account Atmospheric
Scattering", SIGGRAPH 1993), in the form Blender 5.0 evaluates it (intern/sky/source/
sky_nishita.cpp for the table, Cycles' kernel/svm/sky.h for its lookup; bpy 5.0.1, read, not
copied):
- geometry: Earth radius 6360 km, atmosphere radius 6420 km; altitude clamped to [1 m,
  59.999 km];
- densities: molecules exp(-h / 8 km), aerosols exp(-h / 1.2 km), ozone a tent
  max(0, 1 - |h - 25 km| / 15 km), each times its node density;
- 21 wavelengths 380 ... 780 nm (20 nm apart): the sun's irradiance above the atmosphere,
  Rayleigh scattering and ozone absorption coefficients per wavelength (tables below), aerosol
  scattering 2e-5 / m at every wavelength, extinction 1.11 times that; phases: Rayleigh
  3 / (16 pi) (1 + mu^2), aerosols Cornette-Shanks with g = 0.76;
- in-scattering along the view ray to the atmosphere's edge in 32 equal segments (each at its
  middle, the view ray's optical depth including the segment), the sun's optical depth from each
  point by an 8-node Gauss-Laguerre rule (nodes x_i / 25 of the segment to the edge, weights
  w_i e^x_i / 25: computed here with numpy's laggauss), no light where the planet hides the sun;
- the spectrum to CIE XYZ by the 1931 colour-matching functions at the 21 wavelengths times
  20 nm; XYZ -> linear Rec.709, negatives clamped (as the other sky types).
Cycles tabulates it in a 512 x 256 image: rows y >= 128 at elevation (pi / 2) (y / 128 - 1)^2,
columns x < 256 at azimuth 2 pi x / 512 - pi from the sun (the rest mirrored), the rows below
128 the horizon row faded by (1 - 2.5 sin e')^3, e' = (pi / 2) (y / 128 - 1)^2 (black from
sin e' = 0.4); it reads the image bilinearly at v = sign(e) sqrt(|e| / (pi / 2)) / 2 + 1/2 for
elevation e, below the horizon too (measured: the kernel source read has a separate fade there
that bpy 5.0.1's Cycles does not apply). `sky_table` builds that image, `table_radiance` reads
it so: within 4e-4 of Cycles at every direction (tests/render/test_sky_cycles.py).

The sun disc (Sun Size, at least 0.0005 rad) has radiance E_sun T / Omega with T the
transmittance of air and aerosols (no ozone), interpolated between the disc's bottom and top
edges (each at least at the horizon), limb darkening 1 - 0.6 (1 - sqrt(1 - (r / R)^2)) (mean
0.8) and Sun Intensity; none when its top is below the horizon. `sun_light` returns it as a
sun lamp of the disc's angle and irradiance."""

import functools
import math

import numpy as np

EARTH_R = 6360e3               # m
ATMOS_R = 6420e3               # m
RAYLEIGH_SCALE = 8e3           # m
MIE_SCALE = 1.2e3              # m
MIE_COEFF = 2e-5               # 1/m
MIE_EXTINCTION = 1.11
MIE_G = 0.76
STEPS = 32
TABLE_W, TABLE_H = 512, 256    # Cycles' image
MIN_SUN_SIZE = 0.0005
STEP_LAMBDA = 20.0             # nm

# sun irradiance above the atmosphere (W m^-2 nm^-1), 380 ... 780 nm
IRRADIANCE = np.array([
    1.45756829855592995315, 1.56596305559738380175, 1.65148449067670455293,
    1.71496242737209314555, 1.75797983805020541226, 1.78256407885924539336,
    1.79095108475838560302, 1.78541550133410664714, 1.76815554864306845317,
    1.74122069647250410362, 1.70647127164943679389, 1.66556087452739887134,
    1.61993437242451854274, 1.57083597368892080581, 1.51932335059305478886,
    1.46628494965214395407, 1.41245852740172450623, 1.35844961970384092709,
    1.30474913844739281998, 1.25174963272610817455, 1.19975998755420620867])
# Rayleigh scattering (1/m)
RAYLEIGH = np.array([
    5.424820087636473e-05, 4.418549866505454e-05, 3.635151910165377e-05,
    3.017929012024763e-05, 2.526320226989157e-05, 2.130859310621843e-05,
    1.809838025320633e-05, 1.547057129129042e-05, 1.330284977336850e-05,
    1.150184784075764e-05, 9.99557429990163e-06, 8.72799973630707e-06,
    7.65513700977967e-06, 6.74217203751443e-06, 5.96134125832052e-06,
    5.29034598065810e-06, 4.71115687557433e-06, 4.20910481110487e-06,
    3.77218381260133e-06, 3.39051255477280e-06, 3.05591531679811e-06])
# ozone absorption (1/m)
OZONE = np.array([
    3.25126849861e-09, 5.85395365047e-09, 1.977191155085e-08, 7.309568762914e-08,
    2.0084561514287e-07, 4.0383958096161e-07, 6.3551335912363e-07, 9.6707041180970e-07,
    1.54797400424410e-06, 2.09038647223331e-06, 2.46128056164565e-06, 2.73551299461512e-06,
    2.15125863128643e-06, 1.59051840791988e-06, 1.12356197979857e-06, 7.3527551487574e-07,
    4.6450130357806e-07, 3.3096079921048e-07, 2.2512612292678e-07, 1.4879129266490e-07,
    1.6828623364192e-07])
# CIE 1931 2-degree colour-matching functions x, y, z at 380 ... 780 nm
CMF = np.array([
    [0.00136800000, 0.00003900000, 0.00645000100], [0.01431000000, 0.00039600000, 0.06785001000],
    [0.13438000000, 0.00400000000, 0.64560000000], [0.34828000000, 0.02300000000, 1.74706000000],
    [0.29080000000, 0.06000000000, 1.66920000000], [0.09564000000, 0.13902000000, 0.81295010000],
    [0.00490000000, 0.32300000000, 0.27200000000], [0.06327000000, 0.71000000000, 0.07824999000],
    [0.29040000000, 0.95400000000, 0.02030000000], [0.59450000000, 0.99500000000, 0.00390000000],
    [0.91630000000, 0.87000000000, 0.00165000100], [1.06220000000, 0.63100000000, 0.00080000000],
    [0.85444990000, 0.38100000000, 0.00019000000], [0.44790000000, 0.17500000000, 0.00002000000],
    [0.16490000000, 0.06100000000, 0.00000000000], [0.04677000000, 0.01700000000, 0.00000000000],
    [0.01135916000, 0.00410200000, 0.00000000000], [0.00289932700, 0.00104700000, 0.00000000000],
    [0.00069007860, 0.00024920000, 0.00000000000], [0.00016615050, 0.00006000000, 0.00000000000],
    [0.00004150994, 0.00001499000, 0.00000000000]])


def _laguerre():
    x, w = np.polynomial.laguerre.laggauss(8)
    return x / 25.0, w * np.exp(x) / 25.0


NODES, WEIGHTS = _laguerre()


def _densities(h):
    """Molecules, aerosols, ozone at altitudes h (m): three arrays."""
    return (np.exp(-h / RAYLEIGH_SCALE), np.exp(-h / MIE_SCALE),
            np.maximum(0.0, 1.0 - np.abs(h - 25e3) / 15e3))


def _exit(r2, mu):
    """Distance to the atmosphere's edge from a point at squared radius r2 (m^2) along a unit
    direction whose dot product with the point's position is mu (m)."""
    return -mu + np.sqrt(np.maximum(mu * mu - r2 + ATMOS_R ** 2, 0.0))


def _optical_depth(r2, mu):
    """The three optical depths (density times metres) to the atmosphere's edge from points
    (r2, mu as in _exit), by the Gauss-Laguerre rule."""
    length = _exit(r2, mu)
    out = [np.zeros_like(length) for _ in range(3)]
    for x, w in zip(NODES, WEIGHTS):
        s = x * length
        for acc, dens in zip(out, _densities(np.sqrt(r2 + 2.0 * s * mu + s * s) - EARTH_R)):
            acc += w * dens
    return [acc * length for acc in out]


def _phases(mu):
    g2 = MIE_G * MIE_G
    rayleigh = 0.1875 / math.pi * (1.0 + mu * mu)
    mie = 3.0 * (1.0 - g2) * (1.0 + mu * mu) / (
        8.0 * math.pi * (2.0 + g2) * (1.0 + g2 - 2.0 * MIE_G * mu) ** 1.5)
    return rayleigh, mie


def single_scattering(dirs, sun, altitude, scale):
    """XYZ (..., 3) in-scattered along unit view directions `dirs` (..., 3) from the altitude
    (m), the sun towards unit `sun`; `scale` the densities' factors (air, aerosol, ozone)."""
    d = np.asarray(dirs, np.float64)
    sun = np.asarray(sun, np.float64)
    r0 = EARTH_R + altitude                   # the camera at (0, 0, r0)
    seg = _exit(r0 * r0, r0 * d[..., 2]) / STEPS
    t = (np.arange(STEPS) + 0.5).reshape((STEPS,) + (1,) * seg.ndim) * seg[None]  # (S, ...)
    r2 = r0 * r0 + 2.0 * t * r0 * d[..., 2] + t * t              # |P|^2 at the segments
    mu = r0 * sun[2] + t * (d @ sun)                              # P . sun
    dens = [k * x for k, x in zip(scale, _densities(np.sqrt(r2) - EARTH_R))]
    view = [np.cumsum(x, axis=0) * seg for x in dens]             # up to each segment's end
    light = [k * x for k, x in zip(scale, _optical_depth(r2, mu))]
    # the planet hides the sun: a downward sun ray that meets the sphere (as Blender tests it)
    lit = (4.0 * mu * mu - 4.0 * (r2 - EARTH_R ** 2) < 0.0) if sun[2] < 0.0 else \
        np.ones(r2.shape, bool)
    pr, pm = _phases(d @ sun)
    spectrum = np.zeros(seg.shape + (21,))
    for wl in range(21):
        tau = (view[0] + light[0]) * RAYLEIGH[wl] + \
            (view[1] + light[1]) * (MIE_EXTINCTION * MIE_COEFF) + (view[2] + light[2]) * OZONE[wl]
        scat = dens[0] * (pr * RAYLEIGH[wl]) + dens[1] * (pm * MIE_COEFF)
        spectrum[..., wl] = np.sum(np.where(lit, np.exp(-tau) * scat, 0.0), axis=0)
    spectrum *= IRRADIANCE * seg[..., None]
    return spectrum @ CMF * STEP_LAMBDA


def _clamp_altitude(altitude):
    a = float(altitude) if math.isfinite(float(altitude)) else 1.0
    return min(max(a, 1.0), 59999.0)


@functools.lru_cache(maxsize=4)
def sky_table(sun_elevation, altitude, air, aerosol, ozone):
    """Cycles' 512 x 256 XYZ image of one sky (the sun at azimuth 0, between columns 255 and
    256), read-only."""
    alt = _clamp_altitude(altitude)
    half_w, half_h = TABLE_W // 2, TABLE_H // 2
    sun = np.array([math.cos(sun_elevation), 0.0, math.sin(sun_elevation)])
    lat = 0.5 * math.pi * (np.arange(half_h, TABLE_H) / half_h - 1.0) ** 2
    lon = 2.0 * math.pi / TABLE_W * np.arange(half_w) - math.pi
    cl = np.cos(lat)[:, None]
    dirs = np.stack([cl * np.cos(lon)[None], cl * np.sin(lon)[None],
                     np.broadcast_to(np.sin(lat)[:, None], (len(lat), half_w))], axis=-1)
    upper = single_scattering(dirs, sun, alt, np.array([air, aerosol, ozone], np.float64))
    table = np.zeros((TABLE_H, TABLE_W, 3))
    table[half_h:, :half_w] = upper
    table[half_h:, half_w:] = upper[:, ::-1]
    z = np.sin(0.5 * math.pi * (np.arange(half_h) / half_h - 1.0) ** 2)
    fade = np.where(z < 0.4, (1.0 - 2.5 * z) ** 3, 0.0)
    table[:half_h] = table[half_h][None] * fade[:, None, None]
    table.setflags(write=False)
    return table


def _bilinear(table, u, v):
    """Cycles' linear image lookup at (u, v) in [0, 1): x wraps, y clamps."""
    h, w = table.shape[:2]
    x = u * w - 0.5
    y = np.clip(v * h - 0.5, 0.0, h - 1.0)
    x0 = np.floor(x).astype(int)
    y0 = np.minimum(np.floor(y).astype(int), h - 2)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    x0, x1 = x0 % w, (x0 + 1) % w
    return ((table[y0, x0] * (1 - fx) + table[y0, x1] * fx) * (1 - fy) +
            (table[y0 + 1, x0] * (1 - fx) + table[y0 + 1, x1] * fx) * fy)


def table_radiance(table, dirs, sun_rotation, matrix):
    """Linear RGB (..., 3) of the sky (no disc) for unit directions `dirs` (..., 3), z up, the
    sun at Blender's Sun Rotation; `matrix` XYZ -> RGB."""
    d = np.asarray(dirs, np.float64)
    z = np.clip(d[..., 2], -1.0, 1.0)
    # azimuth from the sun's (towards (sin r, cos r)); the table is symmetric about it
    delta = np.arctan2(d[..., 0], d[..., 1]) - sun_rotation
    u = np.mod(0.5 + delta / (2.0 * math.pi), 1.0)
    elev = np.arcsin(z)
    v = np.sign(elev) * np.sqrt(np.abs(elev) / (0.5 * math.pi)) * 0.5 + 0.5
    return np.maximum(_bilinear(table, u, v) @ matrix.T, 0.0)


def sun_light(sun_elevation, sun_size, sun_intensity, altitude, air, aerosol, matrix):
    """The sun disc as (angular diameter, RGB irradiance on a surface facing it), or None when
    its top is below the horizon: the mean of the edges' radiance times the solid angle and
    limb darkening's mean 0.8, E_sun T 0.8 in XYZ (T the edges' mean transmittance)."""
    size = max(float(sun_size), MIN_SUN_SIZE)
    top = sun_elevation + 0.5 * size
    if top <= 0.0:
        return None
    r0 = EARTH_R + _clamp_altitude(altitude)
    edges = np.maximum([sun_elevation - 0.5 * size, top], 0.0)
    od = _optical_depth(np.full(2, r0 * r0), r0 * np.sin(edges))
    t = np.exp(-(RAYLEIGH[None] * od[0][:, None] * air +
                 MIE_EXTINCTION * MIE_COEFF * od[1][:, None] * aerosol)).mean(axis=0)
    rgb = np.maximum(((IRRADIANCE * t) @ CMF * STEP_LAMBDA) @ matrix.T, 0.0)
    return size, 0.8 * rgb * max(float(sun_intensity), 0.0)
