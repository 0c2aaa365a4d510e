// The shadow terminator's lift (integrator/terminator.h) on a coarse sphere's triangle with
// radial vertex normals: the lifted point closes most of the flat face's gap to the sphere and
// stays under the corners' tangent planes, goes inward seen from the back, none at the corners
// or for flat normals; the amount's fade-in.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.h"
#include "core/sampling.h"
#include "integrator/terminator.h"

using namespace lantern;

namespace {

struct Tri {
    Vec3 p[3], n[3];
    uint32_t idx[3] = {0, 1, 2};
    float cutoff = 0.1f;
    SceneView view() const {
        SceneView s;
        s.positions = p;
        s.normals = n;
        s.indices = idx;
        s.tri_terminator = &cutoff;
        s.num_triangles = 1;
        return s;
    }
};

// A triangle of a sphere of radius r about the origin, corners at the given directions.
Tri sphere_tri(Vec3 a, Vec3 b, Vec3 c, float r) {
    Tri t;
    const Vec3 d[3] = {normalize(a), normalize(b), normalize(c)};
    for (int k = 0; k < 3; ++k) {
        t.p[k] = d[k] * r;
        t.n[k] = d[k];
    }
    return t;
}

}  // namespace

TEST(Terminator, LiftReachesTheSmoothSurface) {
    // a coarse triangle (about 40 degrees across), as an unsubdivided low-poly mesh has
    const float r = 2.0f;
    const Tri t = sphere_tri({1, 0, 0.2f}, {0.6f, 0.7f, 0.1f}, {0.7f, 0.1f, 0.8f}, r);
    const SceneView s = t.view();
    const Vec3 ng = normalize(cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
    ASSERT_GT(dot(ng, t.p[0]), 0.0f);  // outward
    // the corners' tangent planes meet at most r / cos(the widest corner-to-corner half-angle)
    float cos_half = 1.0f;
    for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b)
            cos_half = ::fminf(cos_half, sqrtf(0.5f * (1.0f + dot(t.n[a], t.n[b]))));
    Pcg32 rng = Pcg32::for_path(7, 1, 2);
    double gap = 0.0, short_of_sphere = 0.0;
    for (int i = 0; i < 2000; ++i) {
        const Vec2 b = sample_triangle(rng.uniform2());
        const Vec3 p = t.p[0] * (1.0f - b.x - b.y) + t.p[1] * b.x + t.p[2] * b.y;
        const Vec3 q = p + terminator_lift(s, 0, p, ng);
        // out of the face, not past the corners' tangent planes
        EXPECT_GE(dot(q - p, ng), -1e-6f);
        EXPECT_LE(length(q), r / cos_half * (1.0f + 1e-4f));
        gap += r - length(p);
        short_of_sphere += ::fmaxf(r - length(q), 0.0f);
        // seen from the back (the mesh's inside): lifted inward, never outward
        const Vec3 q2 = p + terminator_lift(s, 0, p, -ng);
        EXPECT_LE(dot(q2 - p, ng), 1e-6f);
    }
    // the flat face lies well inside the sphere; lifted, most of that gap is closed
    EXPECT_GT(gap / 2000.0, 0.02);
    EXPECT_LT(short_of_sphere, 0.2 * gap);
    // the corners do not move
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(length(terminator_lift(s, 0, t.p[k], ng)), 0.0f, 1e-5f);
}

TEST(Terminator, FlatNormalsAndOffNoLift) {
    Tri t = sphere_tri({1, 0, 0.2f}, {0.6f, 0.7f, 0.1f}, {0.7f, 0.1f, 0.8f}, 1.0f);
    const Vec3 ng = normalize(cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
    for (Vec3& n : t.n) n = ng;  // flat shaded
    const SceneView s = t.view();
    const Vec3 p = (t.p[0] + t.p[1] + t.p[2]) * (1.0f / 3.0f);
    EXPECT_NEAR(length(terminator_lift(s, 0, p, ng)), 0.0f, 1e-6f);
    // no offset: the origin is the hit point and nothing passes under the face
    t.cutoff = 0.0f;
    const SceneView off = t.view();
    const Vec3 w = normalize(ng * -0.05f + normalize(t.p[1] - t.p[0]));
    EXPECT_FALSE(terminator_passes(off, 0, w, ng, normalize(ng + (t.p[1] - t.p[0]))));
    EXPECT_EQ(terminator_origin(off, 0, p, ng, ng, w, 0.0f).x, p.x);
    // strands and out-of-range prims read no offset
    EXPECT_EQ(terminator_cutoff(s, 1), 0.0f);
    EXPECT_EQ(terminator_cutoff(s, -1), 0.0f);
}

TEST(Terminator, AmountFadesIn) {
    const Vec3 ng{0, 0, 1};
    const Vec3 ns = normalize(Vec3{0.3f, 0, 1});
    const float cutoff = 0.1f;
    auto dir = [](float deg) {  // in the xz plane, deg above the face's plane toward +x
        const float a = deg * kPi / 180.0f;
        return Vec3{cosf(a), 0.0f, sinf(a)};
    };
    // high above the face: none; under the face but above the shading normal's horizon: all
    EXPECT_EQ(terminator_amount(cutoff, ng, ns, dir(60.0f)), 0.0f);
    EXPECT_EQ(terminator_amount(cutoff, ng, ns, dir(-5.0f)), 1.0f);
    // between: in (0, 1), decreasing as the light rises
    float prev = 1.0f;
    for (float deg = 0.0f; deg <= 12.0f; deg += 1.0f) {
        const float a = terminator_amount(cutoff, ng, ns, dir(deg));
        EXPECT_LE(a, prev + 1e-6f);
        prev = a;
    }
    EXPECT_GT(terminator_amount(cutoff, ng, ns, dir(3.0f)), 0.0f);
    EXPECT_LT(terminator_amount(cutoff, ng, ns, dir(5.0f)), 1.0f);
}
