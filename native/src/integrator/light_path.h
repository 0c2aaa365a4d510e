// Emission sampling: a light sub-path's first vertex and direction for every light type, with
// the terms BDPT's MIS needs later (Georgiev, "Implementing VCM", sec. 5; SmallVCM lights.hxx):
// pdf_emit (area x solid angle), pdf_direct (area, or solid angle for distant lights), the cosine
// at the light and the delta flags. weight = le * cos_light / pdf_emit is the sample's flux.
#pragma once

#include "scene/lights.h"

namespace lantern {

struct EmissionSample {
    Vec3 p;            // origin (for sun and world: a point on a disk outside the scene)
    Vec3 n;            // geometric normal on the emitting side; zero for points, sun, world
    Vec3 d;            // unit direction of emission
    Vec3 le;           // radiance along d (intensity W/sr for delta-position lights, irradiance
                       // W/m^2 for a delta sun), cone attenuation included
    float pdf_emit;    // pdf of (p, d): area (1 for delta position) x solid angle (1 for delta
                       // direction), without the light pick probability
    float pdf_direct;  // pdf of p when next-event estimation samples it: area for finite lights
                       // (1 for delta position), solid angle of -d for sun/world (1 for delta)
    float cos_light;   // |cos| between d and n at the light; 1 for points, sun and world
    bool delta_pos;    // point/spot of radius 0: no surface to hit
    bool delta_dir;    // sun with angle 0: one direction
    bool finite;       // false for sun and world (vertex at infinity)
    bool valid;
};

// Soft-falloff point/spot lights of radius > 0 (Blender's default) are a disk that faces the
// shaded point: sample_emission and emission_pdf leave them out (invalid, 0); their light paths
// leave the centre and take y0 at the first hit (soft_light_path.h, docs/lvc_notes.md).
LANTERN_HD inline bool light_receiver_dependent(const Light& l) {
    return (l.type == kLightPoint || l.type == kLightSpot) && l.radius > 0.0f && l.soft_falloff;
}

// The disk of radius r about the scene's centre perpendicular to d, r behind the centre: every
// ray along d that can reach the scene crosses it when every vertex lies within r of the centre.
LANTERN_HD inline Vec3 distant_disk_point(const SceneView& s, Vec3 d, Vec2 u, float r) {
    Frame f = Frame::from_normal(d);
    Vec2 q = sample_concentric_disk(u);
    return s.scene_center + (f.s * q.x + f.t * q.y - d) * r;
}

// Which disk sun and world paths leave. kBoundingDisk: the bounding box's sphere (scene_radius),
// the disk emission_pdf() assumes, for every integrator whose MIS weighs light paths (bdpt, lvc,
// cis). kTightDisk: the sphere through the farthest vertex (emit_radius), for the pure light
// tracer, which never evaluates emission_pdf(): about a ball 2/3 of the bounding disk's paths
// miss (lt's world furnace: 0.18 % -> 0.09 % noise); bdpt with it got 5x noisier (its MIS then
// favours light paths, whose pdf_emit grew: tried and reverted, tests/README.md "Noticed").
enum DistantDisk : int { kBoundingDisk = 0, kTightDisk = 1 };

// Emission sample of light l from two 2D numbers: u_pos chooses the point, u_dir the direction;
// `time`: the light path's shutter time (a moving emissive triangle's point and normal then).
LANTERN_HD inline EmissionSample sample_emission(const SceneView& s, const Light& l, Vec2 u_pos,
                                                 Vec2 u_dir, float time,
                                                 DistantDisk disk = kBoundingDisk) {
    EmissionSample es{};
    es.valid = false;
    es.finite = true;
    es.cos_light = 1.0f;
    float pdf_dir = 0.0f;
    switch (l.type) {
    case kLightPoint:
    case kLightSpot: {
        if (light_receiver_dependent(l)) return es;
        if (l.radius <= 0.0f) {
            es.p = l.position;
            es.delta_pos = true;
            es.pdf_direct = 1.0f;
            if (l.type == kLightSpot) {  // uniform in the cone; the smoothstep stays in le
                Frame f = Frame::from_normal(-l.frame.axis(2));
                es.d = f.to_world(sample_uniform_cone(u_dir, l.cos_half_spot, &pdf_dir));
            } else {
                es.d = sample_uniform_sphere(u_dir, &pdf_dir);
            }
            es.le = l.intensity;
            es.pdf_emit = pdf_dir;
        } else {  // sphere: uniform point, cosine direction about the outward normal
            Vec3 n = sample_uniform_sphere(u_pos, nullptr);
            Frame f = Frame::from_normal(n);
            es.p = l.position + n * l.radius;
            es.n = n;
            es.d = f.to_world(sample_cosine_hemisphere(u_dir, &pdf_dir));
            es.cos_light = dot(es.d, n);
            es.le = l.radiance;
            // next-event estimation samples the visible cap uniformly in solid angle: its area
            // pdf depends on the receiver; 1/area is the receiver-free stand-in (see notes)
            es.pdf_direct = 1.0f / (4.0f * kPi * l.radius * l.radius);
            es.pdf_emit = es.pdf_direct * pdf_dir;
        }
        if (l.type == kLightSpot) es.le = es.le * spot_attenuation(l, es.d);
        break;
    }
    case kLightArea: {  // front side (local -Z) only
        Vec3 n = -l.frame.axis(2);
        Frame f = Frame::from_normal(n);
        es.p = area_point(l, u_pos);
        es.n = n;
        es.d = f.to_world(sample_cosine_hemisphere(u_dir, &pdf_dir));
        es.cos_light = dot(es.d, n);
        es.le = l.radiance;
        // (a rectangle's next-event density follows its solid angle from the receiver:
        // 1/area is the receiver-free stand-in, as for spheres; direct_pdf_receiver_ratio)
        es.pdf_direct = 1.0f / l.area;
        es.pdf_emit = es.pdf_direct * pdf_dir;
        break;
    }
    case kLightTriangle: {  // both sides: the side is the first bit of u_dir.x
        Vec3 a = triangle_vertex(s, l.triangle, 0), b = triangle_vertex(s, l.triangle, 1),
             c = triangle_vertex(s, l.triangle, 2);
        float area = l.area;
        if (s.motion.num_objects > 0) {  // a moving mesh's: where it is at the path's time
            const MovedTriangle mt = light_triangle_at(s, l, time);
            a = mt.v[0];
            b = mt.v[1];
            c = mt.v[2];
            area = mt.area;
        }
        Vec2 bc = sample_triangle(u_pos);
        Vec3 n = normalize(cross(b - a, c - a));
        Vec2 ud = u_dir;
        if (ud.x < 0.5f) {
            ud.x *= 2.0f;
        } else {
            ud.x = 2.0f * ud.x - 1.0f;
            n = -n;
        }
        Frame f = Frame::from_normal(n);
        es.p = a * (1.0f - bc.x - bc.y) + b * bc.x + c * bc.y;
        es.n = n;
        es.d = f.to_world(sample_cosine_hemisphere(ud, &pdf_dir));
        es.cos_light = dot(es.d, n);
        es.le = triangle_emission(s, l, bc);
        es.pdf_direct = 1.0f / area;
        es.pdf_emit = es.pdf_direct * 0.5f * pdf_dir;
        break;
    }
    case kLightSun:
    case kLightWorld: {
        es.finite = false;
        if (l.type == kLightWorld) {
            Vec3 to_light;
            if (!world_sample(s, l, u_dir, &to_light, &pdf_dir, &es.le)) return es;
            es.d = -to_light;
        } else if (l.cos_sun >= 1.0f) {
            es.d = l.direction;
            es.le = l.intensity;
            es.delta_dir = true;
            pdf_dir = 1.0f;
        } else {
            Frame f = Frame::from_normal(l.direction);
            es.d = f.to_world(sample_uniform_cone(u_dir, l.cos_sun, &pdf_dir));
            es.le = l.radiance;
        }
        const float r = disk == kTightDisk ? s.emit_radius : s.scene_radius;
        es.p = distant_disk_point(s, es.d, u_pos, r);
        es.pdf_direct = pdf_dir;  // solid angle, as next-event estimation samples it
        es.pdf_emit = pdf_dir / (kPi * r * r);
        break;
    }
    default:
        return es;
    }
    es.valid = es.pdf_emit > 0.0f && es.cos_light > 0.0f && !is_black(es.le) && is_finite(es.d);
    return es;
}

// Flux of an emission sample, le * cos / pdf_emit (its expectation is the light's power; for
// sun and world, the power through the scene's bounding disk).
LANTERN_HD inline Vec3 emission_weight(const EmissionSample& es) {
    return es.le * (es.cos_light / es.pdf_emit);
}

// Where next-event estimation's area density of a light point depends on the receiver (a
// sphere light's visible cap, a rectangle sampled by solid angle: lights.h spherical_rect, a
// soft-falloff disk by the cone it subtends), EmissionSample::pdf_direct holds the
// receiver-free 1/area (a soft disk's: 1 / (pi r^2)). This is the factor that makes it the
// density with which next-event estimation from receiver p samples light point y0 (normal n0)
// along unit direction wi at distance dist: 1 where it samples by area (or not by position).
// (A soft disk's needs wi alone: its plane through the centre faces p.)
LANTERN_HD inline float direct_pdf_receiver_ratio(const Light& l, Vec3 p, Vec3 wi, float dist,
                                                  Vec3 n0) {
    if (light_receiver_dependent(l))
        return soft_cone_area_pdf(l, p, wi) * (kPi * l.radius * l.radius);
    const bool sphere = (l.type == kLightPoint || l.type == kLightSpot) && l.radius > 0.0f;
    SphericalRect sr;
    if (!sphere && !spherical_rect(l, p, &sr)) return 1.0f;
    const float pdf_a = light_pdf_w(l, p, wi, dist, n0) * fabsf(dot(wi, n0)) / (dist * dist);
    return pdf_a * (sphere ? 4.0f * kPi * l.radius * l.radius : l.area);
}

// ---- Emission pdfs of a given emitted ray (what BDPT needs when a camera path hits a light) ----
struct EmissionPdf {
    float pdf_emit;    // as EmissionSample::pdf_emit
    float pdf_direct;  // as EmissionSample::pdf_direct
};

// Pdfs with which sample_emission (kBoundingDisk) would produce a ray leaving light l along d,
// from a point with geometric normal n (finite surface lights; ignored for points, sun, world),
// at shutter time `time` (a moving emissive triangle's area then: light_area_at).
LANTERN_HD inline EmissionPdf emission_pdf(const SceneView& s, const Light& l, Vec3 n, Vec3 d,
                                           float time) {
    EmissionPdf r{0.0f, 0.0f};
    const float inv_disk = 1.0f / (kPi * s.scene_radius * s.scene_radius);
    switch (l.type) {
    case kLightPoint:
    case kLightSpot:
        if (light_receiver_dependent(l)) return r;
        if (l.radius <= 0.0f) {
            r.pdf_direct = 1.0f;
            if (l.type == kLightPoint) {
                r.pdf_emit = 0.25f * kInvPi;
            } else if (dot(d, -l.frame.axis(2)) >= l.cos_half_spot) {
                r.pdf_emit = pdf_uniform_cone(l.cos_half_spot);
            }
        } else {
            r.pdf_direct = 1.0f / (4.0f * kPi * l.radius * l.radius);
            r.pdf_emit = r.pdf_direct * pdf_cosine_hemisphere(dot(d, n));
        }
        return r;
    case kLightArea:
        r.pdf_direct = 1.0f / l.area;
        r.pdf_emit = r.pdf_direct * pdf_cosine_hemisphere(dot(d, -l.frame.axis(2)));
        return r;
    case kLightTriangle:
        r.pdf_direct = 1.0f / light_area_at(s, l, time);
        r.pdf_emit = r.pdf_direct * 0.5f * pdf_cosine_hemisphere(fabsf(dot(d, n)));
        return r;
    case kLightSun:
        if (l.cos_sun >= 1.0f) {
            r.pdf_direct = 1.0f;
            r.pdf_emit = inv_disk;
        } else if (dot(d, l.direction) >= l.cos_sun) {
            r.pdf_direct = pdf_uniform_cone(l.cos_sun);
            r.pdf_emit = r.pdf_direct * inv_disk;
        }
        return r;
    case kLightWorld:
        r.pdf_direct = world_pdf_w(s, -d);
        r.pdf_emit = r.pdf_direct * inv_disk;
        return r;
    default:
        return r;
    }
}

}  // namespace lantern
