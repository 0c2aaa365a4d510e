// HostScene::build_light_linking: Cycles' light linking (an emitter's Receiver collection) as
// receiver sets: each mesh is in one set (MeshInput::light_set, 0..63, which lantern/scene.py and
// the add-on's export/linking.py number), each light lights the sets of its mask. The view's
// arrays (tri_light_set, light_receivers) stay null where no mesh or light is linked.
#include "scene/scene.h"

namespace lantern {

void HostScene::build_light_linking(const SceneInput& in) {
    bool linked = false;
    for (const MeshInput& m : in.meshes)
        linked |= m.light_set != 0 || m.emitter_receivers != kAllReceivers;
    for (const LightInput& l : in.lights) linked |= l.receivers != kAllReceivers;
    if (!linked) return;
    tri_light_set_.assign(tri_material_.size(), 0);
    std::vector<uint64_t> tri_mask(tri_material_.size(), kAllReceivers);
    for (size_t k = 0; k < mesh_ranges_.size() && k < in.meshes.size(); ++k) {
        const MeshRange& r = mesh_ranges_[k];
        for (int t = r.tri_begin; t < r.tri_begin + r.tri_count; ++t) {
            tri_light_set_[t] = uint8_t(in.meshes[k].light_set & 63);
            tri_mask[t] = in.meshes[k].emitter_receivers;
        }
    }
    light_receivers_.assign(lights_.size(), kAllReceivers);
    for (size_t k = 0; k < lights_.size(); ++k) {
        const Light& l = lights_[k];
        if (l.type == kLightTriangle) {
            light_receivers_[k] = tri_mask[l.triangle];
        } else if (k < lamp_input_.size() && lamp_input_[k] >= 0) {
            light_receivers_[k] = in.lights[lamp_input_[k]].receivers;
        }
    }
}

}  // namespace lantern
