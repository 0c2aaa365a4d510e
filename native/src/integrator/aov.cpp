// First-hit data passes (integrator/aov.h): one camera ray per sample through the CPU
// accelerator, the hit resolved as the path tracer resolves it (pt_surface, material_at), so
// normal maps, textures, alpha and mixes read the same. Each pixel is written by one task, its
// samples in order: the same seed gives the same passes, bit for bit.
#include "integrator/aov.h"

#include "backend/backend.h"
#include "integrator/camera.h"
#include "integrator/pt.h"

namespace lantern {

namespace {

constexpr float kMissDepth = 1e10f;  // Cycles' Depth on the background
constexpr uint64_t kAovStream = 0xA0F5EED5ull;  // keeps these rays apart from the render's

// The diffuse lobes' colour seen from cosine mu (Cycles' Diffuse Color: the diffuse closure's
// weight): the base under the principled specular layer, coat and sheen.
Vec3 diffuse_color_leaf(const Material& m, float mu) {
    switch (m.type) {
    case kMaterialDiffuse:
    case kMaterialTranslucent:
        return m.base_color;
    case kMaterialPrincipled: {
        const PrincipledWeights w = principled_weights(m);
        const float base = w.spec * (1.0f - principled_spec_albedo(m, mu));
        return m.base_color * principled_below_coat(m, mu, mu) * base;
    }
    default:
        return vec3(0.0f);
    }
}

Vec3 diffuse_color(const Material& m, float mu) {
    if (m.type != kMaterialMix) return diffuse_color_leaf(m, mu);
    Vec3 c = vec3(0.0f);
    Material tmp;
    for (int i = 0; i < m.mix_count; ++i) {
        if (m.mix_leaf[i]) c += diffuse_color_leaf(mix_leaf_at(m, i, tmp), mu) * m.mix_weight[i];
    }
    return c;
}

struct PixelSum {
    double depth = 0, ddepth = 0;
    double n[3] = {0, 0, 0}, dc[3] = {0, 0, 0}, em[3] = {0, 0, 0};
    double alb[3] = {0, 0, 0}, dn[3] = {0, 0, 0};
    void add(double* a, Vec3 v) {
        a[0] += v.x;
        a[1] += v.y;
        a[2] += v.z;
    }
};

struct CameraAxes {
    Vec3 o, x, y, fwd;
};

// Cycles' camera space for the denoiser's normal: x right, y up, z along the view.
Vec3 to_camera(const CameraAxes& c, Vec3 n) { return {dot(n, c.x), dot(n, c.y), dot(n, c.fwd)}; }

// ---- One sample of one pixel ----
void sample_pixel(const SceneView& s, const CpuBackend& accel, const CameraAxes& cam,
                  const AovSettings& st, int pixel, int k, PixelSum& sum) {
    Rng rng = Rng::for_pixel(st.seed ^ kAovStream, uint64_t(pixel), uint64_t(k));
    // Cycles' sample 0 goes through the pixel centre (its filter sample is (0.5, 0.5)), so its
    // Depth, read from that sample, is the centre's; the others sample the pixel filter
    Ray ray = k == 0 ? camera_ray(s.camera, float(pixel % s.camera.width) + 0.5f,
                                  float(pixel / s.camera.width) + 0.5f,
                                  s.camera.lens_radius > 0.0f
                                      ? sample_aperture(s.camera, rng.uniform2()) : Vec2{})
                     : generate_camera_ray(s.camera, pixel, rng);
    HitRecord hit = accel.intersect(ray, RayKind::kCamera);
    const Vec3 world = s.world_light >= 0 ? s.lights[s.world_light].radiance : vec3(0.0f);
    if (hit.prim < 0) {
        if (k == 0) sum.depth = kMissDepth;
        sum.add(sum.alb, world);
        return;
    }
    SurfaceHit h = surface_of_hit(s, hit.prim, hit.uv, ray.o, ray.d, hit.t, ray.time);  // strands too
    MaterialScratch scratch;
    const Material* m = &material_at(s, s.tri_material[hit.prim], h.st, scratch);
    const float mu = fmaxf(dot(-ray.d, h.ns), 0.0f);
    if (k == 0) sum.depth = dot(h.p - cam.o, cam.fwd);
    sum.add(sum.n, h.ns);
    sum.add(sum.dc, diffuse_color(*m, mu));
    sum.add(sum.em, m->emission);
    // ---- Denoising features: through mirrors and clear glass to the first rough surface ----
    Vec3 tp = vec3(1.0f);
    for (int bounce = 0;; ++bounce) {
        const Frame frame = h.frame();
        const Vec3 wo = frame.to_local(-ray.d);
        Vec3 u{rng.uniform(), rng.uniform(), rng.uniform()};
        BsdfSample bs = material_sample(*m, h.front, wo, u, Transport::Radiance, h.coat_n,
                                        frame.to_local(h.ng));
        if (!material_is_delta(*m) || bounce >= st.max_passthrough) {
            if (bs.valid && is_finite(bs.weight)) sum.add(sum.alb, tp * bs.weight);
            sum.add(sum.dn, to_camera(cam, h.ns));
            sum.ddepth += dot(h.p - cam.o, cam.fwd);
            return;
        }
        if (!bs.valid || !is_finite(bs.weight)) return;
        tp = tp * bs.weight;
        const Vec3 wi = frame.to_world(bs.wi);
        ray = Ray{offset_ray_origin(h.p, h.ng, wi, s.offset_scale), wi, 0.0f, kInf};
        hit = accel.intersect(ray, RayKind::kIndirect);
        if (hit.prim < 0) {
            sum.add(sum.alb, tp * world);
            return;
        }
        h = surface_of_hit(s, hit.prim, hit.uv, ray.o, ray.d, hit.t, ray.time);
        m = &material_at(s, s.tri_material[hit.prim], h.st, scratch);
    }
}

}  // namespace

AovImages render_aovs(const SceneInput& in, const AovSettings& st) {
    if (st.spp < 1 || st.spp > 1 << 16)
        throw std::invalid_argument("AOV spp must be in [1, 65536]");
    AovImages out;
    HostScene scene(in);
    out.warnings = scene.warnings();
    const SceneView& s = scene.view();
    CpuBackend accel(s, st.threads, out.warnings);
    const int w = s.camera.width, h = s.camera.height;
    out.width = w;
    out.height = h;
    const size_t n = size_t(w) * size_t(h);
    out.depth.assign(n, 0.0f);
    out.denoising_depth.assign(n, 0.0f);
    for (auto* v : {&out.normal, &out.diffuse_color, &out.emission, &out.denoising_albedo,
                    &out.denoising_normal})
        v->assign(3 * n, 0.0f);
    const Transform& t = s.camera.to_world;
    CameraAxes cam{t.origin(), normalize(t.vector(vec3(1.0f, 0.0f, 0.0f))),
                   normalize(t.vector(vec3(0.0f, 1.0f, 0.0f))),
                   normalize(t.vector(vec3(0.0f, 0.0f, -1.0f)))};
    const double inv = 1.0 / st.spp;
    accel.for_all(int(n), [&](int p) {
        PixelSum sum;
        for (int k = 0; k < st.spp; ++k) sample_pixel(s, accel, cam, st, p, k, sum);
        out.depth[p] = float(sum.depth);
        out.denoising_depth[p] = float(sum.ddepth * inv);
        for (int c = 0; c < 3; ++c) {
            out.normal[3 * p + c] = float(sum.n[c] * inv);
            out.diffuse_color[3 * p + c] = float(sum.dc[c] * inv);
            out.emission[3 * p + c] = float(sum.em[c] * inv);
            out.denoising_albedo[3 * p + c] = float(sum.alb[c] * inv);
            out.denoising_normal[3 * p + c] = float(sum.dn[c] * inv);
        }
    }, 16);
    return out;
}

}  // namespace lantern
