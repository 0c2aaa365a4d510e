// HostScene::build_light_linking: Cycles' light linking (an emitter's Receiver collection) as
// receiver sets, and shadow linking (its Blocker collection) as blocker sets, built alike: each mesh is in one set (MeshInput::light_set, 0..63, which lantern/scene.py and
// the add-on's export/linking.py number), each light lights the sets of its mask. The view's
// arrays (tri_light_set, light_receivers) stay null where no mesh or light is linked.
#include "scene/scene.h"

namespace lantern {

namespace {

// Per triangle its mesh's set; per light its mask (lamps: lamp_mask(input index); emissive
// triangles: their mesh's emitter_mask); none of it where nothing is linked.
template <class MeshSet, class MeshMask, class LampMask>
void build_sets(const std::vector<MeshRange>& ranges, const SceneInput& in,
                const std::vector<Light>& lights, const std::vector<int32_t>& lamp_input,
                size_t num_tris, MeshSet mesh_set, MeshMask emitter_mask, LampMask lamp_mask,
                std::vector<uint8_t>& tri_set, std::vector<uint64_t>& light_mask) {
    bool linked = false;
    for (const MeshInput& m : in.meshes)
        linked |= mesh_set(m) != 0 || emitter_mask(m) != kAllReceivers;
    for (const LightInput& l : in.lights) linked |= lamp_mask(l) != kAllReceivers;
    if (!linked) return;
    tri_set.assign(num_tris, 0);
    std::vector<uint64_t> tri_mask(num_tris, kAllReceivers);
    for (size_t k = 0; k < ranges.size() && k < in.meshes.size(); ++k) {
        for (int t = ranges[k].tri_begin; t < ranges[k].tri_begin + ranges[k].tri_count; ++t) {
            tri_set[t] = uint8_t(mesh_set(in.meshes[k]) & 63);
            tri_mask[t] = emitter_mask(in.meshes[k]);
        }
    }
    light_mask.assign(lights.size(), kAllReceivers);
    for (size_t k = 0; k < lights.size(); ++k) {
        if (lights[k].type == kLightTriangle)
            light_mask[k] = tri_mask[lights[k].triangle];
        else if (k < lamp_input.size() && lamp_input[k] >= 0)
            light_mask[k] = lamp_mask(in.lights[lamp_input[k]]);
    }
}

}  // namespace

void HostScene::build_light_linking(const SceneInput& in) {
    build_sets(mesh_ranges_, in, lights_, lamp_input_, tri_material_.size(),
               [](const MeshInput& m) { return m.light_set; },
               [](const MeshInput& m) { return m.emitter_receivers; },
               [](const LightInput& l) { return l.receivers; }, tri_light_set_, light_receivers_);
    build_sets(mesh_ranges_, in, lights_, lamp_input_, tri_material_.size(),
               [](const MeshInput& m) { return m.shadow_set; },
               [](const MeshInput& m) { return m.emitter_blockers; },
               // a lamp without Cast Shadow traces no shadow ray in Cycles, so its Blocker
               // collection changes nothing: it is not shadow-linked (difftest4 9008)
               [](const LightInput& l) { return l.cast_shadow ? l.blockers : kAllReceivers; },
               tri_shadow_set_, light_blockers_);
}

// A light whose blocker sets hold every set a primitive is in (a Blocker collection of every
// object: the difftester's probe, or a user's) casts the shadows it would unlinked, yet as a
// shadow-linked light it would get next-event estimation alone (pt_light_linking.h): unbiased,
// but on a near-specular lobe reflecting a large lamp a heavy-tailed estimator where MIS is not
// (bench/results/2026-12-06-nee10022: -2.9 % at 64 spp, the deficit shrinking with samples). Such
// a light is not shadow-linked; with none left the arrays go, and the scene renders as unlinked.
void HostScene::drop_redundant_shadow_links() {
    if (light_blockers_.empty()) return;
    uint64_t used = 0;  // the shadow sets of every triangle and strand segment
    for (const uint8_t set : tri_shadow_set_) used |= uint64_t(1) << (set & 63);
    bool linked = false;
    for (uint64_t& mask : light_blockers_) {
        if ((mask & used) == used) mask = kAllReceivers;
        linked |= mask != kAllReceivers;
    }
    if (!linked) {
        light_blockers_.clear();
        tri_shadow_set_.clear();
    }
}

}  // namespace lantern
