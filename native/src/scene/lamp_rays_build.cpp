// HostScene::build_lamp_rays: a lamp's own ray visibility (Blender's Object > Visibility > Ray
// Visibility on a light: Diffuse, Glossy, Transmission, Volume Scatter) as the RayKinds that
// see each light, and kLampNoShadow where the lamp's Cast Shadow is off; emissive triangles
// (their object's flags: tri_rays) and the world (world_rays) keep every kind here. The view's
// array stays null where every lamp is seen by every kind and casts shadows, so that such
// scenes run as before (integrator/pt_ray_visibility.h).
#include "scene/scene.h"

namespace lantern {

void HostScene::build_lamp_rays(const SceneInput& in) {
    bool any = false;
    for (const LightInput& l : in.lights)
        any |= (l.rays & kRayKindsAll) != kRayKindsAll || !l.cast_shadow;
    if (!any) return;
    light_rays_.assign(lights_.size(), uint8_t(kRayKindsAll));
    for (size_t k = 0; k < lights_.size(); ++k)
        if (lights_[k].type != kLightTriangle && k < lamp_input_.size() && lamp_input_[k] >= 0) {
            const LightInput& l = in.lights[lamp_input_[k]];
            light_rays_[k] = uint8_t((l.rays & kRayKindsAll) | (l.cast_shadow ? 0 : kLampNoShadow));
        }
}

}  // namespace lantern
