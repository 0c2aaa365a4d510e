// Motion blur's host side (scene/motion.h, docs/motion_blur.md): each moving mesh's matrices at
// the shutter's steps decomposed into rotation, translation and scale-and-shear (as Cycles
// interpolates them), checked (a singular or non-finite step, a moving emitter: a warning and
// the mesh stays where it was exported), and bounded over the shutter for the top-level BVH.
#include "scene/motion_build.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "scene/scene.h"

namespace lantern {

namespace {

// The unit quaternion (x, y, z, w) of rotation matrix r (Shepperd's choice of the largest term).
void quaternion_of(const double r[3][3], float q[4]) {
    const double tr = r[0][0] + r[1][1] + r[2][2];
    double x, y, z, w;
    if (tr > 0.0) {
        const double s = 2.0 * std::sqrt(tr + 1.0);
        w = 0.25 * s;
        x = (r[2][1] - r[1][2]) / s;
        y = (r[0][2] - r[2][0]) / s;
        z = (r[1][0] - r[0][1]) / s;
    } else if (r[0][0] >= r[1][1] && r[0][0] >= r[2][2]) {
        const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 + r[0][0] - r[1][1] - r[2][2]));
        x = 0.25 * s;
        w = (r[2][1] - r[1][2]) / s;
        y = (r[0][1] + r[1][0]) / s;
        z = (r[0][2] + r[2][0]) / s;
    } else if (r[1][1] >= r[2][2]) {
        const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 + r[1][1] - r[0][0] - r[2][2]));
        y = 0.25 * s;
        w = (r[0][2] - r[2][0]) / s;
        x = (r[0][1] + r[1][0]) / s;
        z = (r[1][2] + r[2][1]) / s;
    } else {
        const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 + r[2][2] - r[0][0] - r[1][1]));
        z = 0.25 * s;
        w = (r[1][0] - r[0][1]) / s;
        x = (r[0][2] + r[2][0]) / s;
        y = (r[1][2] + r[2][1]) / s;
    }
    const double l = std::sqrt(x * x + y * y + z * z + w * w);
    q[0] = float(x / l), q[1] = float(y / l), q[2] = float(z / l), q[3] = float(w / l);
}

bool same_matrix(const float* a, const float* b) {
    for (int k = 0; k < 12; ++k)
        if (a[k] != b[k]) return false;
    return true;
}

}  // namespace

bool decompose_motion_step(const float m[16], MotionStep* out) {
    for (int k = 0; k < 12; ++k)
        if (!std::isfinite(m[k])) return false;
    // columns of the 3x3 part, orthonormalised in order (Gram-Schmidt): A = Q U
    double c[3][3];
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) c[j][i] = m[4 * i + j];
    auto dot3 = [](const double* a, const double* b) {
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    };
    double u[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (int j = 0; j < 3; ++j) {
        for (int k = 0; k < j; ++k) {
            u[k][j] = dot3(c[k], c[j]);
            for (int i = 0; i < 3; ++i) c[j][i] -= u[k][j] * c[k][i];
        }
        u[j][j] = std::sqrt(dot3(c[j], c[j]));
        if (!(u[j][j] > 1e-12 * (1.0 + std::fabs(m[4 * 0 + j]) + std::fabs(m[4 * 1 + j]) +
                                 std::fabs(m[4 * 2 + j]))))
            return false;  // singular (a zero scale, collapsed axes)
        for (int i = 0; i < 3; ++i) c[j][i] /= u[j][j];
    }
    double r[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r[i][j] = c[j][i];
    const double det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) -
                       r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                       r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    if (det < 0.0) {  // a mirror: the rotation is -Q, the scale -U
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) r[i][j] = -r[i][j], u[i][j] = -u[i][j];
    }
    quaternion_of(r, out->q);
    for (int i = 0; i < 3; ++i) out->t[i] = m[4 * i + 3];
    out->u[0] = float(u[0][0]), out->u[1] = float(u[0][1]), out->u[2] = float(u[0][2]);
    out->u[3] = float(u[1][1]), out->u[4] = float(u[1][2]), out->u[5] = float(u[2][2]);
    return true;
}

void motion_world_box(const MotionView& mv, const ObjectMotion& o, const Vec3 box[2],
                      Vec3 out[2]) {
    out[0] = vec3(kInf);
    out[1] = vec3(-kInf);
    if (!(box[0].x <= box[1].x)) return;
    // the box's corners at 16 times per step interval, padded by the farthest a corner moves
    // between two of them (a corner's path between samples stays within that of its chord)
    constexpr int kSub = 16;
    const int n = std::max(2, o.num_steps);
    const int samples = (n - 1) * kSub;
    Vec3 prev[8];
    float pad = 0.0f;
    for (int s = 0; s <= samples; ++s) {
        const float time = float(s) / float(samples);
        const Transform m = object_motion_to_world(mv, o, time);
        for (int c = 0; c < 8; ++c) {
            const Vec3 p{c & 1 ? box[1].x : box[0].x, c & 2 ? box[1].y : box[0].y,
                         c & 4 ? box[1].z : box[0].z};
            const Vec3 w = m.point(p);
            out[0] = {std::min(out[0].x, w.x), std::min(out[0].y, w.y), std::min(out[0].z, w.z)};
            out[1] = {std::max(out[1].x, w.x), std::max(out[1].y, w.y), std::max(out[1].z, w.z)};
            if (s > 0) pad = std::max(pad, length(w - prev[c]));
            prev[c] = w;
        }
    }
    float far = 0.0f;
    for (int a = 0; a < 3; ++a) far = std::max({far, std::fabs(out[0][a]), std::fabs(out[1][a])});
    pad += 1e-5f * (max_component(out[1] - out[0]) + far);
    out[0] = out[0] - vec3(pad);
    out[1] = out[1] + vec3(pad);
}

namespace {

bool matrices_move(const std::vector<float>& m) {
    for (size_t k = 16; k + 16 <= m.size(); k += 16)
        if (!same_matrix(&m[0], &m[k])) return true;
    return false;
}

}  // namespace

std::string motion_reason(const SceneInput& in) {
    std::string why = motion_geometry_reason(in);
    if (why.empty() && matrices_move(in.camera_motion)) why = "motion blur (the camera moves)";
    return why;
}

std::string motion_geometry_reason(const SceneInput& in) {
    const auto moves = matrices_move;
    for (const MeshInput& m : in.meshes)
        if (moves(m.motion)) return "motion blur (mesh '" + m.name + "' moves)";
    for (const MeshInput& m : in.meshes) {  // deformation blur
        const size_t per = m.positions.size();
        for (size_t k = per; per > 0 && k < m.deform.size(); ++k)
            if (m.deform[k] != m.deform[k % per])
                return "motion blur (mesh '" + m.name + "' deforms)";
    }
    for (const CurveInput& c : in.curves) {  // strands (scene/curve_motion.cpp)
        const size_t per = c.points.size();
        for (size_t k = per; per > 0 && k < c.deform.size(); ++k)
            if (c.deform[k] != c.deform[k % per])
                return "motion blur (strands '" + c.name + "' move)";
        if (!c.deform_radius.empty()) return "motion blur (strands '" + c.name + "' move)";
        if (moves(c.motion)) return "motion blur (strands '" + c.name + "' move)";
    }
    return "";
}

void HostScene::build_motion(const SceneInput& in) {
    motion_steps_.clear();
    motion_objects_.clear();
    view_.motion = MotionView{};
    motion_deforms_.clear();
    motion_corners_.clear();
    bool any = !in.camera_motion.empty() || !curve_keys_.empty();
    for (const MeshInput& m : in.meshes) any |= !m.motion.empty() || !m.deform.empty();
    for (const CurveInput& c : in.curves) any |= !c.motion.empty();
    if (!any) return;
    // subsurface: the walk's rays carry the path's time, its entry and exit are where the mesh
    // is then (pt_sss.h, bdpt_sss.h). Volumes: every ray of a path through media carries its
    // time (pt_volume.h), and a rigidly moving mesh whose media are homogeneous crosses into
    // them where it is then (pt_cross_boundary); one with a heterogeneous medium (its fits and
    // density are the frame's) or that deforms stays where it was exported. Moving strands in
    // media: every medium ray, shadow segment and connection carries the path's time
    // (MotionView::rays_timed), so the curve queries place them there (test_motion_media_strands.py).
    // 0: no medium; 1: homogeneous media only; 2: a heterogeneous one
    auto bounds_volume = [&](const MeshRange& r) {
        int kind = 0;
        for (int t = r.tri_begin; t < r.tri_begin + r.tri_count; ++t) {
            const uint32_t mat = tri_material_[size_t(t)];
            if (mat >= material_medium_.size() || material_medium_[mat] < 0) continue;
            kind = std::max(kind, media_[size_t(material_medium_[mat])].hetero ? 2 : 1);
        }
        return kind;
    };
    // a moving heterogeneous volume moves where its density can follow it: every medium of the
    // mesh's triangles that is heterogeneous is a density program's (a Volume object's grid is
    // not moved: Cycles moves its voxels only by velocity grids) and bounded by this mesh alone
    // (its density then read through this mesh's matrix at the ray's time, medium_ray_exported)
    auto hetero_movable = [&](const MeshRange& r) {
        std::vector<int32_t> mine;
        for (int t = r.tri_begin; t < r.tri_begin + r.tri_count; ++t) {
            const uint32_t mat = tri_material_[t];
            if (mat >= material_medium_.size() || material_medium_[mat] < 0) continue;
            const int32_t med = material_medium_[mat];
            const Medium& md = media_[size_t(med)];
            if (!md.hetero) continue;
            if (md.density_grid >= 0 || md.density_prog < 0) return false;
            if (std::find(mine.begin(), mine.end(), med) == mine.end()) mine.push_back(med);
        }
        for (size_t t = 0; t < tri_material_.size(); ++t) {
            if (int(t) >= r.tri_begin && int(t) < r.tri_begin + r.tri_count) continue;
            const uint32_t mat = tri_material_[t];
            if (mat < material_medium_.size() && material_medium_[mat] >= 0 &&
                std::find(mine.begin(), mine.end(), material_medium_[mat]) != mine.end())
                return false;  // another mesh bounds it too
        }
        return true;
    };
    motion_media_.clear();
    std::vector<int32_t> volumes;  // the moving volumes' meshes (the camera's check below)
    // steps of one matrix list; false (with a warning naming `who`) where one is unusable
    auto add_steps = [&](const std::vector<float>& mats, const std::string& who,
                         bool rigid) -> int {
        const size_t n = mats.size() / 16;
        if (mats.size() % 16 != 0 || n < 2) {
            warnings_.push_back(who + ": its motion needs at least 2 steps of 4x4 matrices (got " +
                                std::to_string(mats.size()) + " numbers); rendered without "
                                "motion blur");
            return -1;
        }
        bool still = true;
        for (size_t k = 1; k < n; ++k) still &= same_matrix(&mats[0], &mats[16 * k]);
        if (still) return 0;
        const size_t first = motion_steps_.size();
        for (size_t k = 0; k < n; ++k) {
            MotionStep st;
            if (!decompose_motion_step(&mats[16 * k], &st)) {
                motion_steps_.resize(first);
                warnings_.push_back(who + ": its matrix at motion step " + std::to_string(k) +
                                    " is singular or not finite; rendered without motion blur "
                                    "(where it is at the frame)");
                return -1;
            }
            if (rigid) {
                st.u[0] = st.u[3] = st.u[5] = 1.0f;
                st.u[1] = st.u[2] = st.u[4] = 0.0f;
            }
            if (k > 0) {  // the shorter way round: q and -q are the same rotation
                const MotionStep& p = motion_steps_.back();
                const float d = p.q[0] * st.q[0] + p.q[1] * st.q[1] + p.q[2] * st.q[2] +
                                p.q[3] * st.q[3];
                if (d < 0.0f)
                    for (float& x : st.q) x = -x;
            }
            motion_steps_.push_back(st);
        }
        return int(n);
    };
    for (size_t k = 0; k < in.meshes.size() && k < mesh_ranges_.size(); ++k) {
        const MeshInput& m = in.meshes[k];
        if (m.motion.empty() && m.deform.empty()) continue;
        const std::string who = "mesh '" + m.name + "'";
        const MeshRange& r = mesh_ranges_[k];
        if (r.tri_count == 0) continue;
        const int volume = media_.empty() ? 0 : bounds_volume(r);
        const std::string still_volume = who + " bounds a heterogeneous volume that cannot "
                                               "follow it (a density grid, or other meshes bound "
                                               "it too): not motion-blurred (rendered where it "
                                               "is at the frame)";
        DeformMesh dm{};
        bool deforms = false;
        if (!m.deform.empty()) {  // deformation blur (scene/deform_build.cpp)
            std::string warning;
            const size_t corners = motion_corners_.size();
            deforms = build_deform(m, r, indices_, motion_corners_, &dm, &warning);
            if (!warning.empty()) warnings_.push_back(warning);
            // (an emitter deforms: its light is sampled where it is at the path's time,
            // scene/lights.h light_triangle_at)
            if (deforms && volume) {
                motion_corners_.resize(corners);
                deforms = false;
                warnings_.push_back(who + " bounds a volume: its deformation is not "
                                          "motion-blurred (rendered as at the frame)");
            }
        }
        Transform base = transform_from_rows(m.motion_base), base_inv;
        const size_t first = motion_steps_.size();
        int n = 0;
        if (!m.motion.empty()) {
            if (!transform_inverse(base, &base_inv)) {
                warnings_.push_back(who + ": the matrix it was exported with is singular or "
                                    "not finite; rendered without motion blur");
                n = -1;
            } else {
                n = add_steps(m.motion, who, false);
            }
            // (an emitter moves: its light is sampled where it is at the path's time, the
            // light tree's bounds stay the frame's: scene/lights.h light_triangle_at)
            if (n > 0 && volume == 2 && !hetero_movable(r)) {
                motion_steps_.resize(first);
                warnings_.push_back(still_volume);
                n = -1;
            }
        }
        if (n < 0 && deforms) {  // its transform unusable: its deformation is not blurred either
            motion_corners_.resize(size_t(dm.first));
            deforms = false;
        }
        if (n <= 0 && deforms) {  // it only deforms: identity steps place it
            base = Transform{};
            for (int a = 0; a < 3; ++a) base.m[a][a] = 1.0f;
            base_inv = base;
            MotionStep id{{0.0f, 0.0f, 0.0f, 1.0f}, {0.0f, 0.0f, 0.0f}, {1, 0, 0, 1, 0, 1}};
            motion_steps_.push_back(id);
            motion_steps_.push_back(id);
            n = 2;
        }
        if (n <= 0) continue;
        if (volume) volumes.push_back(int32_t(k));
        if (volume == 2) {  // its heterogeneous media follow it (hetero_movable)
            if (motion_media_.empty()) motion_media_.assign(media_.size(), -1);
            for (int t = r.tri_begin; t < r.tri_begin + r.tri_count; ++t) {
                const uint32_t mat = tri_material_[t];
                if (mat < material_medium_.size() && material_medium_[mat] >= 0 &&
                    media_[size_t(material_medium_[mat])].hetero)
                    motion_media_[size_t(material_medium_[mat])] =
                        int32_t(motion_objects_.size());
            }
        }
        if (deforms) motion_deforms_.push_back(dm);
        ObjectMotion o{};
        o.tri_begin = r.tri_begin;
        o.tri_count = r.tri_count;
        o.first_step = int32_t(first);
        o.num_steps = n;
        o.mesh = int32_t(k);
        o.deform = deforms ? int32_t(motion_deforms_.size()) - 1 : -1;
        o.base = base;
        o.base_inv = base_inv;
        motion_objects_.push_back(o);
    }
    int camera_first = 0, camera_steps = 0;
    if (!in.camera_motion.empty()) {
        camera_first = int(motion_steps_.size());
        camera_steps = std::max(0, add_steps(in.camera_motion, "the camera", true));
        // camera rays start in the medium where the camera is at the frame (medium_build.cpp)
        for (int k = 0; k < camera_steps && !media_.empty(); ++k) {
            const float time = float(k) / float(camera_steps - 1);
            const Transform c = motion_at(motion_steps_.data(), camera_first, camera_steps, time);
            if (camera_medium_at(c.origin()) != view_.camera_medium) {
                warnings_.push_back("the camera crosses a volume's boundary over the shutter: "
                                    "its rays start in the medium it is in at the frame");
                break;
            }
        }
    }
    // strand sets moving with their objects (docs/motion_blur.md "Strands of a turning object"):
    // their steps as a mesh's, the segments left where they were exported
    curve_sets_.clear();
    for (size_t k = 0; k < in.curves.size() && k < curve_ranges_.size(); ++k) {
        const CurveInput& c = in.curves[k];
        if (c.motion.empty() || curve_ranges_[k].second == 0) continue;
        const std::string who = "curves " + std::to_string(k) + " ('" + c.name + "')";
        CurveSetMotion cs{};
        cs.o.base = transform_from_rows(c.motion_base);
        if (!transform_inverse(cs.o.base, &cs.o.base_inv)) {
            warnings_.push_back(who + ": the matrix it was exported with is singular or not "
                                "finite; rendered without its object's motion");
            continue;
        }
        const size_t first = motion_steps_.size();
        const int n = add_steps(c.motion, who, false);
        if (n <= 0) continue;
        cs.o.tri_begin = curve_ranges_[k].first;
        cs.o.tri_count = curve_ranges_[k].second;
        cs.o.first_step = int32_t(first);
        cs.o.num_steps = n;
        cs.o.mesh = cs.o.deform = -1;
        cs.radius_scale = 1.0f;
        for (int st = 0; st < n; ++st) {  // the largest stretch of a step (power iteration)
            const Transform m = transform_mul(
                motion_compose(motion_steps_[first + st].q, motion_steps_[first + st].t,
                               motion_steps_[first + st].u), cs.o.base_inv);
            Vec3 v = normalize(vec3(1.0f, 0.7f, 0.3f));
            float stretch = 0.0f;
            for (int it = 0; it < 32; ++it) {
                const Vec3 a = m.vector(v);
                stretch = length(a);
                const Vec3 b = vec3(m.m[0][0] * a.x + m.m[1][0] * a.y + m.m[2][0] * a.z,
                                    m.m[0][1] * a.x + m.m[1][1] * a.y + m.m[2][1] * a.z,
                                    m.m[0][2] * a.x + m.m[1][2] * a.y + m.m[2][2] * a.z);
                if (!(length(b) > 0.0f)) break;
                v = normalize(b);
            }
            cs.radius_scale = std::max(cs.radius_scale, stretch * 1.001f);
        }
        curve_sets_.push_back(cs);
    }
    view_.curves.sets = curve_sets_.empty() ? nullptr : curve_sets_.data();
    view_.curves.num_sets = int32_t(curve_sets_.size());
    // moving strands (scene/curve_motion.cpp's keys, or sets moving with their objects)
    const bool curves = !curve_keys_.empty() || !curve_sets_.empty();
    if (motion_objects_.empty() && camera_steps < 2 && !curves) return;
    view_.motion.steps = motion_steps_.data();
    view_.motion.objects = motion_objects_.empty() ? nullptr : motion_objects_.data();
    view_.motion.num_objects = int32_t(motion_objects_.size());
    view_.motion.deforms = motion_deforms_.empty() ? nullptr : motion_deforms_.data();
    view_.motion.deform_corners = motion_corners_.empty() ? nullptr : motion_corners_.data();
    view_.motion.camera_first = camera_first;
    view_.motion.camera_steps = camera_steps;
    view_.motion.curves = curves ? 1 : 0;
    view_.motion.medium_objects = motion_media_.empty() ? nullptr : motion_media_.data();
    const char* untimed = std::getenv("LANTERN_TEST_UNTIMED_MEDIA");  // (MotionView)
    view_.motion.media_untimed = untimed && std::string(untimed) == "1" ? 1 : 0;
    // the light tree's bounds take in where moving emitters go over the shutter (as the
    // frame's bounds alone sampled a light that moves far from them with a poor importance);
    // LANTERN_LIGHT_TREE_SHUTTER=0 keeps the frame's, for benchmarks (bench/light_tree_motion.py)
    const char* shutter_env = std::getenv("LANTERN_LIGHT_TREE_SHUTTER");
    std::vector<Vec3> shutter;
    if (light_tree_on_ && !(shutter_env && std::string(shutter_env) == "0") &&
        light_shutter_boxes(view_, lights_, shutter)) {
        build_light_tree(lights_, positions_, indices_, light_tree_, &shutter);
        view_.light_tree = light_tree_.nodes.data();
        view_.num_tree_nodes = int32_t(light_tree_.nodes.size());
        view_.distant_lights = light_tree_.distant.empty() ? nullptr : light_tree_.distant.data();
        view_.num_distant_lights = int32_t(light_tree_.distant.size());
    }
    // camera rays start in the frame's medium: a moving volume that may reach the camera says so
    for (const ObjectMotion& o : motion_objects_) {
        if (std::find(volumes.begin(), volumes.end(), o.mesh) == volumes.end()) continue;
        Vec3 box[2] = {vec3(kInf), vec3(-kInf)}, swept[2];
        for (int t = o.tri_begin; t < o.tri_begin + o.tri_count; ++t)
            for (int j = 0; j < 3; ++j) {
                const Vec3 p = positions_[indices_[3 * size_t(t) + size_t(j)]];
                box[0] = {std::min(box[0].x, p.x), std::min(box[0].y, p.y),
                          std::min(box[0].z, p.z)};
                box[1] = {std::max(box[1].x, p.x), std::max(box[1].y, p.y),
                          std::max(box[1].z, p.z)};
            }
        motion_world_box(view_.motion, o, box, swept);
        const Vec3 c = view_.camera.to_world.origin();
        if (c.x >= swept[0].x && c.y >= swept[0].y && c.z >= swept[0].z && c.x <= swept[1].x &&
            c.y <= swept[1].y && c.z <= swept[1].z) {
            warnings_.push_back("mesh '" + in.meshes[size_t(o.mesh)].name + "' bounds a moving "
                                "volume that may reach the camera: its rays start in the medium "
                                "it is in at the frame");
        }
    }
}

}  // namespace lantern
