"""d60: an independent Monte Carlo reference (numpy, no renderer) for D60's path class: the
radiance a diffuse floor point reflects of the single-scattered glow of its own emission in a
homogeneous isotropic fog. Floor: a square of side W at z = 0 emitting Le upwards (Lambertian),
albedo rho; the point x0 at its centre; fog sigma_t (grey), sigma_s (RGB), phase 1/(4 pi).
R = rho E_cos[ L_glow(w) ],  L_glow(w) = int_0^inf sigma_s e^{-sigma_t t} S(x0 + t w) dt,
S(p) = 1/(4 pi) int_floor Le e^{-sigma_t r} cos_l / r^2 dA (what a fog point receives, per
unit phase). Sampled: w cosine, t ~ sigma_t e^{-sigma_t t}, the floor point by a uniform
direction down from the fog point (bounded estimator).
    python bench/d60_reference.py [N]"""
import sys
import numpy as np
N = int(sys.argv[1]) if len(sys.argv) > 1 else 4_000_000
W = 12.0
dens = 0.0724
C = np.array([0.4734, 0.9031, 0.8324])
sig_t, sig_s = dens, dens * C
Le = 2.7666 * np.array([0.3251, 0.4531, 0.9528])
rho = np.array([0.8792, 0.4678, 0.5486])
rng = np.random.default_rng(1)
vals = []
for _ in range(N // 1_000_000):
    n = 1_000_000
    u1, u2 = rng.random(n), rng.random(n)
    r = np.sqrt(u1); phi = 2 * np.pi * u2
    w = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u1)], 1)
    t = -np.log(1 - rng.random(n)) / sig_t
    p = w * t[:, None]
    # the floor point: a uniform direction down from p (pdf 1 / (2 pi) in solid angle), so
    # that S = 1/(4 pi) Le e^{-sigma_t r} 2 pi where it lands on the floor
    v1, v2 = rng.random(n), rng.random(n)
    cz = 1 - v1
    rr = np.sqrt(1 - cz * cz); ph = 2 * np.pi * v2
    dist = p[:, 2] / cz
    qx = p[:, 0] + rr * np.cos(ph) * dist
    qy = p[:, 1] + rr * np.sin(ph) * dist
    inside = (np.abs(qx) < W / 2) & (np.abs(qy) < W / 2)
    S = np.where(inside, 0.5 * np.exp(-sig_t * dist), 0.0)   # x Le
    vals.append(S)
S = np.concatenate(vals)
m, se = S.mean(), S.std() / np.sqrt(len(S))
R = rho * (sig_s / sig_t) * Le * m
print("E[S]/Le", m, "+-", se, "(rel", se / m, ")")
print("R (reflected glow, RGB)", R, "rel se", se / m)

# The control: the camera 1 m above x0 looking down at the emission-only floor at bounces 0:
# Le T(1) + int_0^1 sigma_s e^{-sigma_t s} L_s(height 1 - s) ds (single scattering), the
# floor point of S sampled as above.
n = 4_000_000
s_ = rng.random(n)  # uniform over the 1 m segment
h = 1.0 - s_
v1, v2 = rng.random(n), rng.random(n)
cz = 1 - v1
rr = np.sqrt(1 - cz * cz); ph = 2 * np.pi * v2
dist = h / cz
qx, qy = rr * np.cos(ph) * dist, rr * np.sin(ph) * dist
inside = (np.abs(qx) < W / 2) & (np.abs(qy) < W / 2)
Sc = np.where(inside, 0.5 * np.exp(-sig_t * dist), 0.0) * np.exp(-sig_t * s_)
print("down view, emission only, bounces 0:", Le * np.exp(-sig_t) + sig_s * Le * Sc.mean(),
      "(rel se of the fog part", Sc.std() / np.sqrt(n) / Sc.mean(), ")")
