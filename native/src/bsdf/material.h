// A material's BSDF as the integrators see it: one eval/sample pair that dispatches on the
// material type to the lobes of this folder. Local frame: +Z is the shading normal turned to the
// side wo arrives from; `front` says whether that side is the surface's front (outside), which
// fixes the relative index of refraction. Reflection lobes are two-sided (as in Cycles).
// Light paths pass Transport::Importance: refraction then does not divide by eta^2.
#pragma once

#include "bsdf/conductor.h"
#include "bsdf/dielectric.h"
#include "bsdf/lambert.h"
#include "bsdf/multiscatter.h"
#include "bsdf/principled.h"
#include "scene/scene_view.h"

namespace lantern {

// A conductor's Fresnel is Blender's F82-tint (F0 = base_color) or, with kFresnelComplex, the
// exact one of eta + i k, which base_color then scales (Mitsuba's specular_reflectance).
LANTERN_HD inline ConductorParams material_conductor(const Material& m) {
    ConductorParams p = m.fresnel == kFresnelComplex
                            ? conductor_complex(m.roughness, m.eta, m.k)
                            : conductor_f82(m.roughness, m.base_color, m.specular_tint);
    p.beckmann = m.beckmann != 0;
    return p;
}
LANTERN_HD inline Vec3 material_conductor_scale(const Material& m) {
    return m.fresnel == kFresnelComplex ? m.base_color : vec3(1.0f);
}
LANTERN_HD inline DielectricParams material_dielectric(const Material& m, bool front,
                                                       Transport mode) {
    return dielectric(m.roughness, front ? m.ior : 1.0f / m.ior, mode);
}

// True when every lobe of m is a delta distribution: a vertex there cannot be connected to.
LANTERN_HD inline bool material_is_delta(const Material& m) {
    switch (m.type) {
    case kMaterialConductor:
        return conductor_is_delta(material_conductor(m));
    case kMaterialDielectric:
        return dielectric_is_delta(material_dielectric(m, true, Transport::Radiance));
    case kMaterialPrincipled: {  // all delta only without a base and with smooth lobes
        PrincipledWeights w = principled_weights(m);
        return w.spec <= 0.0f && principled_spec_is_delta(m);
    }
    default:
        return false;
    }
}

// True when m can send light to the other side of the surface.
LANTERN_HD inline bool material_transmits(const Material& m) {
    return m.type == kMaterialDielectric || (m.type == kMaterialPrincipled && m.transmission > 0.0f);
}

LANTERN_HD inline BsdfEval material_eval(const Material& m, bool front, Vec3 wo, Vec3 wi,
                                         Transport mode) {
    switch (m.type) {
    case kMaterialConductor: {
        BsdfEval e = conductor_eval(material_conductor(m), wo, wi);
        e.f = e.f * material_conductor_scale(m) *
              ms_scale(m, m.fms_metal, mode == Transport::Radiance ? wo.z : wi.z);
        return e;
    }
    case kMaterialDielectric: {
        BsdfEval e = dielectric_eval(material_dielectric(m, front, mode), wo, wi);
        if (wo.z * wi.z < 0.0f) e.f = e.f * m.base_color;  // transmission tint
        return e;
    }
    case kMaterialPrincipled:
        return principled_eval(m, front, wo, wi, mode);
    default:
        return lambert_eval(m.base_color, wo, wi);
    }
}

// u.x, u.y choose the direction, u.z the lobe event (dielectric reflection or transmission).
LANTERN_HD inline BsdfSample material_sample(const Material& m, bool front, Vec3 wo, Vec3 u,
                                             Transport mode) {
    switch (m.type) {
    case kMaterialConductor: {
        BsdfSample s = conductor_sample(material_conductor(m), wo, Vec2{u.x, u.y});
        s.weight = s.weight * material_conductor_scale(m);
        if (s.valid && !s.delta)
            s.weight = s.weight * ms_scale(m, m.fms_metal,
                                           mode == Transport::Radiance ? wo.z : s.wi.z);
        return s;
    }
    case kMaterialDielectric: {
        BsdfSample s = dielectric_sample(material_dielectric(m, front, mode), wo, Vec2{u.x, u.y}, u.z);
        if (s.valid && wo.z * s.wi.z < 0.0f) s.weight = s.weight * m.base_color;
        return s;
    }
    case kMaterialPrincipled:
        return principled_sample(m, front, wo, u, mode);
    default:
        return lambert_sample(m.base_color, wo, Vec2{u.x, u.y});
    }
}

}  // namespace lantern
