// nanobind bindings: lantern._core. Converts the Python scene dict (docs/scene_format.md,
// Scene.to_native()) into a SceneInput, and exposes Session with the GIL released while
// rendering. Errors in the input surface as ValueError with a message naming the culprit.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <memory>
#include <stdexcept>
#include <system_error>
#include <type_traits>

#include "backend/cpu/embree_loader.h"
#include "backend/cuda/cuda_renderer.h"
#include "integrator/session.h"
#include "python/dict_get.h"

namespace nb = nanobind;
using namespace lantern;

namespace lantern {
void bind_aovs(nb::module_& m, SceneInput (*to_input)(const nb::dict&));  // aov_bindings.cpp
void bind_programs(nb::module_& m);  // program_bindings.cpp
void bind_vdb(nb::module_& m);       // vdb_bindings.cpp
void get_grids(const nb::dict& scene, SceneInput& in);  // vdb_bindings.cpp
void bind_light_probe(nb::module_& m, SceneInput (*to_input)(const nb::dict&));  // light_probe_bindings.cpp

// A homogeneous medium (docs/volumes.md): {"sigma_a", "sigma_s", "emission": rgb, "g": float};
// appended to in.media, its index returned.
int get_medium(const nb::handle& h, const std::string& name, SceneInput& in) {
    nb::dict v = nb::cast<nb::dict>(h);
    MediumInput mi;
    mi.name = name;
    mi.sigma_a = get_vec3(v, "sigma_a", mi.sigma_a);
    mi.sigma_s = get_vec3(v, "sigma_s", mi.sigma_s);
    mi.emission = get_vec3(v, "emission", mi.emission);
    mi.g = get<float>(v, "g", mi.g);
    mi.blackbody_intensity = get<float>(v, "blackbody_intensity", mi.blackbody_intensity);
    mi.temperature = get<float>(v, "temperature", mi.temperature);
    mi.blackbody_tint = get_vec3(v, "blackbody_tint", mi.blackbody_tint);
    mi.flame_emission = get_vec3(v, "flame_emission", mi.flame_emission);
    mi.color_scatter = get_vec3(v, "color_scatter", mi.color_scatter);
    mi.color_absorb = get_vec3(v, "color_absorb", mi.color_absorb);
    mi.color_base = get_vec3(v, "color_base", mi.color_base);
    mi.absorb_alone = get_vec3(v, "absorb_alone", mi.absorb_alone);
    in.media.push_back(mi);
    return int(in.media.size()) - 1;
}

}  // namespace lantern

namespace {

constexpr int kMaxThreads = 4096;  // as python/lantern/session.py

// The world's environment map (docs/scene_format.md): "map" float32 (H, W, 3 or 4).
void get_world_map(const nb::dict& w, SceneInput& in) {
    in.world_visible_camera = get<bool>(w, "visible_camera", true);
    in.world_rays = (get<bool>(w, "visible_diffuse", true) ? kWorldDiffuse : 0u) |
                    (get<bool>(w, "visible_glossy", true) ? kWorldGlossy : 0u) |
                    (get<bool>(w, "visible_transmission", true) ? kWorldTransmission : 0u) |
                    (get<bool>(w, "visible_volume_scatter", true) ? kWorldVolume : 0u);
    if (!has(w, "map")) return;
    nb::ndarray<const float, nb::ndim<3>, nb::c_contig, nb::device::cpu> a;
    if (!nb::try_cast(w["map"], a, false))
        throw std::invalid_argument("world: 'map' must be a C-contiguous float32 (H, W, 3|4) array");
    EnvMapInput& e = in.world_map;
    e.name = get<std::string>(w, "map_name", "");
    e.height = int(a.shape(0));
    e.width = int(a.shape(1));
    e.channels = int(a.shape(2));
    e.pixels.assign(a.data(), a.data() + a.size());
    e.strength = get_vec3(w, "strength", e.strength);
    e.projection = get<std::string>(w, "projection", e.projection);
    if (has(w, "to_map")) {
        auto m = nb::cast<std::vector<float>>(w["to_map"]);
        if (m.size() != 9) throw std::invalid_argument("world 'to_map' needs 9 values");
        for (int k = 0; k < 9; ++k) e.to_map[k] = m[k];
    }
}

SceneInput to_input(const nb::dict& scene) {
    SceneInput in;
    if (has(scene, "film")) {
        nb::dict f = nb::cast<nb::dict>(scene["film"]);
        in.width = get<int>(f, "width", 64);
        in.height = get<int>(f, "height", 64);
        in.filter_width = get<float>(f, "filter_width", 1.5f);
        in.film_transparent = get<bool>(f, "transparent", false);
        in.catcher_mode = get<int>(f, "catcher_mode", 0);
    }
    if (has(scene, "camera")) {
        nb::dict c = nb::cast<nb::dict>(scene["camera"]);
        const std::string type = get<std::string>(c, "type", "perspective");
        in.orthographic = type == "orthographic";
        in.panoramic = type == "equirectangular";
        if (has(c, "longitude") || has(c, "latitude")) {
            auto lon = has(c, "longitude") ? nb::cast<std::vector<float>>(c["longitude"])
                                           : std::vector<float>{-kPi, kPi};
            auto lat = has(c, "latitude") ? nb::cast<std::vector<float>>(c["latitude"])
                                          : std::vector<float>{-0.5f * kPi, 0.5f * kPi};
            if (lon.size() != 2 || lat.size() != 2)
                throw std::invalid_argument("camera 'longitude' and 'latitude' need 2 values");
            const float r[4] = {lon[0], lon[1], lat[0], lat[1]};
            for (int k = 0; k < 4; ++k) in.pano_range[k] = r[k];
        }
        get_matrix(c, "to_world", in.camera_to_world);
        in.camera_motion = get_array<float>(c, "motion", 16, "camera");  // motion blur
        if (has(c, "screen")) {
            auto s = nb::cast<std::vector<float>>(c["screen"]);
            if (s.size() != 4) throw std::invalid_argument("camera 'screen' needs 4 values");
            for (int k = 0; k < 4; ++k) in.screen[k] = s[k];
        }
        if (has(c, "dof")) {
            nb::dict d = nb::cast<nb::dict>(c["dof"]);
            in.lens_radius = get<float>(d, "radius", in.lens_radius);
            in.focus_distance = get<float>(d, "focus_distance", in.focus_distance);
            in.aperture_blades = get<int>(d, "blades", in.aperture_blades);
            in.aperture_rotation = get<float>(d, "rotation", in.aperture_rotation);
            in.aperture_ratio = get<float>(d, "ratio", in.aperture_ratio);
        }
        if (has(c, "clip")) {
            auto s = nb::cast<std::vector<float>>(c["clip"]);
            if (s.size() != 2) throw std::invalid_argument("camera 'clip' needs 2 values");
            in.clip_start = s[0];
            in.clip_end = s[1];
        }
    }
    if (has(scene, "world")) {
        nb::dict w = nb::cast<nb::dict>(scene["world"]);
        in.world_color = get_vec3(w, "color", {});
        get_world_map(w, in);
        if (has(w, "volume")) in.world_medium = get_medium(w["volume"], "world", in);
    }
    get_materials(scene, in);  // material_bindings.cpp
    if (has(scene, "textures")) {
        for (nb::handle h : nb::cast<nb::list>(scene["textures"])) {
            nb::dict t = nb::cast<nb::dict>(h);
            TextureInput ti;
            ti.name = get<std::string>(t, "name", "");
            const std::string who = "texture '" + ti.name + "'";
            nb::ndarray<nb::device::cpu> px;
            if (!has(t, "pixels") || !nb::try_cast(t["pixels"], px, false) || px.ndim() != 3 ||
                px.shape(2) != 4) {
                throw std::invalid_argument(who + ": 'pixels' must be a numpy array of shape "
                                            "(height, width, 4)");
            }
            ti.height = int(px.shape(0));
            ti.width = int(px.shape(1));
            ti.format = get<std::string>(t, "colorspace", "srgb");
            if (px.dtype() == nb::dtype<uint8_t>()) {
                if (ti.format == "float") ti.format = "linear";
                ti.bytes = get_array<uint8_t>(t, "pixels", 1, who);
            } else {
                ti.format = "float";
                ti.floats = get_array<float>(t, "pixels", 1, who);
            }
            ti.wrap = get<std::string>(t, "wrap", ti.wrap);
            ti.interpolation = get<std::string>(t, "interpolation", ti.interpolation);
            ti.output = get<std::string>(t, "output", ti.output);
            if (has(t, "uv_transform")) {
                auto v = nb::cast<std::vector<float>>(t["uv_transform"]);
                if (v.size() != 6)
                    throw std::invalid_argument(who + ": 'uv_transform' needs 6 values");
                for (int k = 0; k < 6; ++k) ti.uv[k] = v[k];
            }
            in.textures.push_back(std::move(ti));
        }
    }
    get_grids(scene, in);  // Volume objects (vdb_bindings.cpp)
    if (has(scene, "node_programs")) {  // compiled node graphs (docs/scene_format.md)
        nb::dict np = nb::cast<nb::dict>(scene["node_programs"]);
        in.programs = get_array<uint32_t>(np, "programs", 6, "node_programs");
        in.program_code = get_array<uint32_t>(np, "code", 4, "node_programs");
        in.program_consts = get_array<float>(np, "consts", 1, "node_programs");
        in.num_attribute_channels = get<int>(np, "attribute_channels", 0);
    }
    if (has(scene, "meshes")) {
        for (nb::handle h : nb::cast<nb::list>(scene["meshes"])) {
            nb::dict m = nb::cast<nb::dict>(h);
            MeshInput mi;
            mi.name = get<std::string>(m, "name", "mesh");
            mi.positions = get_array<float>(m, "positions", 3, "mesh '" + mi.name + "'");
            mi.normals = get_array<float>(m, "normals", 3, "mesh '" + mi.name + "'");
            mi.uvs = get_array<float>(m, "uvs", 2, "mesh '" + mi.name + "'");
            mi.tangents = get_array<float>(m, "tangents", 4, "mesh '" + mi.name + "'");
            mi.indices = get_array<uint32_t>(m, "indices", 3, "mesh '" + mi.name + "'");
            mi.material_ids = get_array<uint32_t>(m, "material_ids", 1, "mesh '" + mi.name + "'");
            if (in.num_attribute_channels > 0)
                mi.attributes = get_array<float>(m, "attributes", 3 * in.num_attribute_channels,
                                                 "mesh '" + mi.name + "'");
            mi.visible_camera = get<bool>(m, "visible_camera", true);
            mi.cast_shadow = get<bool>(m, "cast_shadow", true);
            mi.shadow_catcher = get<bool>(m, "shadow_catcher", false);
            mi.terminator = get<float>(m, "terminator_offset", 0.0f);
            mi.flat = get<bool>(m, "flat_shading", false);
            mi.light_set = get<int>(m, "light_set", 0);
            mi.emitter_receivers = get<uint64_t>(m, "receivers", kAllReceivers);
            mi.shadow_set = get<int>(m, "shadow_set", 0);
            mi.emitter_blockers = get<uint64_t>(m, "blockers", kAllReceivers);
            mi.rays = uint8_t((get<bool>(m, "visible_diffuse", true) ? kRayDiffuse : 0) |
                              (get<bool>(m, "visible_glossy", true) ? kRayGlossy : 0) |
                              (get<bool>(m, "visible_transmission", true) ? kRayTransmission : 0) |
                              (get<bool>(m, "visible_volume_scatter", true) ? kRayVolumeScatter : 0));
            // motion blur: (S, 16) object-to-world matrices at the shutter's steps
            mi.motion = get_array<float>(m, "motion", 16, "mesh '" + mi.name + "'");
            get_matrix(m, "motion_base", mi.motion_base);
            mi.deform = get_array<float>(m, "deform", 3, "mesh '" + mi.name + "'");
            in.meshes.push_back(std::move(mi));
        }
    }
    if (has(scene, "curves")) {  // strands (docs/scene_format.md "curves")
        for (nb::handle h : nb::cast<nb::list>(scene["curves"])) {
            nb::dict c = nb::cast<nb::dict>(h);
            CurveInput ci;
            ci.name = get<std::string>(c, "name", "curves");
            const std::string who = "curves '" + ci.name + "'";
            ci.points = get_array<float>(c, "points", 3, who);
            ci.radius = get_array<float>(c, "radius", 1, who);
            for (uint32_t o : get_array<uint32_t>(c, "offsets", 1, who)) {
                if (o > uint32_t(INT32_MAX))
                    throw std::invalid_argument(who + ": offsets beyond 2^31 points");
                ci.offsets.push_back(int32_t(o));
            }
            ci.material_ids = get_array<uint32_t>(c, "material_ids", 1, who);
            // motion blur: (S * P, 3) points and (S * P,) radii at the shutter's steps
            ci.deform = get_array<float>(c, "deform", 3, who);
            ci.deform_radius = get_array<float>(c, "deform_radius", 1, who);
            // its object's motion: (S, 16) object-to-world at the steps, the exported matrix
            ci.motion = get_array<float>(c, "motion", 16, who);
            get_matrix(c, "motion_base", ci.motion_base);
            ci.visible_camera = get<bool>(c, "visible_camera", true);
            ci.cast_shadow = get<bool>(c, "cast_shadow", true);
            ci.rays = uint8_t((get<bool>(c, "visible_diffuse", true) ? kRayDiffuse : 0) |
                              (get<bool>(c, "visible_glossy", true) ? kRayGlossy : 0) |
                              (get<bool>(c, "visible_transmission", true) ? kRayTransmission : 0) |
                              (get<bool>(c, "visible_volume_scatter", true) ? kRayVolumeScatter : 0));
            ci.light_set = get<int>(c, "light_set", 0);
            ci.shadow_set = get<int>(c, "shadow_set", 0);
            in.curves.push_back(std::move(ci));
        }
    }
    if (has(scene, "lights")) {
        for (nb::handle h : nb::cast<nb::list>(scene["lights"])) {
            nb::dict l = nb::cast<nb::dict>(h);
            LightInput li;
            li.name = get<std::string>(l, "name", "");
            li.type = get<std::string>(l, "type", "");
            get_matrix(l, "to_world", li.to_world);
            li.position = get_vec3(l, "position", {li.to_world[3], li.to_world[7], li.to_world[11]});
            li.direction = get_vec3(l, "direction", li.direction);
            li.power = get_vec3(l, "power", {});
            li.strength = get_vec3(l, "strength", {});
            li.radius = get<float>(l, "radius", 0.0f);
            li.spot_size = get<float>(l, "spot_size", li.spot_size);
            li.spot_blend = get<float>(l, "spot_blend", li.spot_blend);
            li.shape = get<std::string>(l, "shape", li.shape);
            if (has(l, "size")) {
                auto s = nb::cast<std::vector<float>>(l["size"]);
                if (s.size() >= 1) li.size_x = li.size_y = s[0];
                if (s.size() >= 2) li.size_y = s[1];
            }
            li.angle = get<float>(l, "angle", 0.0f);
            li.soft_falloff = get<bool>(l, "soft_falloff", true);
            li.visible_camera = get<bool>(l, "visible_camera", false);
            li.rays = uint8_t((get<bool>(l, "visible_diffuse", true) ? kRayDiffuse : 0) |
                              (get<bool>(l, "visible_glossy", true) ? kRayGlossy : 0) |
                              (get<bool>(l, "visible_transmission", true) ? kRayTransmission : 0) |
                              (get<bool>(l, "visible_volume_scatter", true) ? kRayVolumeScatter : 0));
            li.cast_shadow = get<bool>(l, "cast_shadow", true);
            li.receivers = get<uint64_t>(l, "receivers", kAllReceivers);  // light linking
            li.blockers = get<uint64_t>(l, "blockers", kAllReceivers);    // shadow linking
            li.of_world = get<bool>(l, "of_world", false);
            in.lights.push_back(li);
        }
    }
    return in;
}

SessionSettings to_settings(const nb::dict& d) {
    SessionSettings s;
    s.integrator = get<std::string>(d, "integrator", s.integrator);
    s.backend = get<std::string>(d, "backend", s.backend);
    s.spp_per_iteration = get<int>(d, "spp_per_iteration", s.spp_per_iteration);
    s.max_depth = get<int>(d, "max_depth", s.max_depth);
    s.rr_depth = get<int>(d, "rr_depth", s.rr_depth);
    s.seed = get<uint64_t>(d, "seed", s.seed);
    s.threads = get<int>(d, "threads", s.threads);
    if (d.contains("sort") && !d["sort"].is_none()) s.sort = nb::cast<bool>(d["sort"]) ? 1 : 0;
    s.connections = get<int>(d, "connections", s.connections);
    s.candidates = get<int>(d, "candidates", s.candidates);
    s.light_path_fraction = get<float>(d, "light_path_fraction", s.light_path_fraction);
    s.cis_target = get<std::string>(d, "cis_target", s.cis_target);
    s.naive_ris = get<bool>(d, "naive_ris", s.naive_ris);
    s.soft_visibility = get<bool>(d, "soft_visibility", s.soft_visibility);
    s.naive_map = get<bool>(d, "naive_map", s.naive_map);
    if (d.contains("connection_allocation") && !d["connection_allocation"].is_none())
        s.connection_allocation = nb::cast<bool>(d["connection_allocation"]) ? 1 : 0;
    s.cache_budget_mb = get<int>(d, "cache_budget_mb", s.cache_budget_mb);
    s.light_candidates = get<int>(d, "light_candidates", s.light_candidates);
    s.adaptive_threshold = get<float>(d, "adaptive_threshold", s.adaptive_threshold);
    s.adaptive_min_samples = get<int>(d, "adaptive_min_samples", s.adaptive_min_samples);
    s.adaptive_step = get<int>(d, "adaptive_step", s.adaptive_step);
    s.instancing = get<bool>(d, "instancing", s.instancing);
    s.auto_keep_pilot = get<bool>(d, "auto_keep_pilot", s.auto_keep_pilot);
    s.auto_media = get<bool>(d, "auto_media", s.auto_media);
    s.gpu_checked = get<int>(d, "gpu_checked", s.gpu_checked);  // (session.py, the self-check)
    s.auto_moments = get<bool>(d, "moment_channels", s.auto_moments);  // (tests)
    if (s.threads < 0 || s.threads > kMaxThreads) {
        throw std::invalid_argument("threads must be in [0, " + std::to_string(kMaxThreads) +
                                    "] (0: one per core), got " + std::to_string(s.threads));
    }
    return s;
}

// Raises a Python exception of `type` with `msg` (a C++ exception cannot carry one).
[[noreturn]] void raise(PyObject* type, const std::string& msg) {
    PyErr_SetString(type, msg.c_str());
    throw nb::python_error();
}

void init_session(Session* self, const nb::dict& scene, const nb::dict& settings) {
    SceneInput in;
    SessionSettings st;
    try {
        try {
            in = to_input(scene);
            st = to_settings(settings);
        } catch (const nb::cast_error& e) {
            throw std::invalid_argument(std::string("invalid scene or settings: ") + e.what());
        }
    } catch (const std::invalid_argument& e) {
        throw nb::value_error(e.what());
    } catch (const std::bad_alloc&) {
        raise(PyExc_MemoryError, "out of memory reading the scene");
    }
    // Errors of the build become Python exceptions once the GIL is held again (the
    // gil_scoped_release must be gone before raise() touches Python).
    std::string error;
    PyObject* type = nullptr;
    {
        nb::gil_scoped_release release;
        try {
            new (self) Session(in, st);
        } catch (const std::invalid_argument& e) {
            type = PyExc_ValueError;
            error = e.what();
        } catch (const std::system_error& e) {  // a thread the pool or Embree could not start
            type = PyExc_RuntimeError;
            error = "could not start the render threads (threads=" + std::to_string(st.threads) +
                    "): " + e.what() + "; lower 'threads' or raise the process's limits";
        } catch (const std::bad_alloc&) {
            type = PyExc_MemoryError;
            error = "out of memory building the scene (" + std::to_string(in.width) + "x" +
                    std::to_string(in.height) + " film, " + std::to_string(in.meshes.size()) +
                    " meshes)";
        } catch (const std::exception& e) {
            type = PyExc_RuntimeError;
            error = e.what();
        }
    }
    if (type) raise(type, error);
}

bool step_session(Session& s) {
    std::string error;
    PyObject* type = nullptr;
    bool ok = false;
    {
        nb::gil_scoped_release release;
        try {
            ok = s.step();
        } catch (const std::bad_alloc&) {
            type = PyExc_MemoryError;
            error = "out of memory during step() (" + std::to_string(s.width()) + "x" +
                    std::to_string(s.height()) + " film); the image keeps the samples so far";
        } catch (const std::system_error& e) {
            type = PyExc_RuntimeError;
            error = std::string("step() failed: ") + e.what();
        } catch (const std::exception& e) {
            type = PyExc_RuntimeError;
            error = e.what();
        }
    }
    if (type) raise(type, error);
    return ok;
}

}  // namespace

NB_MODULE(_core, m) {
    m.doc() = "Lantern's native core (CPU and CUDA backends).";
    bind_aovs(m, &to_input);
    bind_programs(m);
    bind_vdb(m);
    bind_light_probe(m, &to_input);
    m.def("embree_available", &embree_available);
    m.def("embree_version", &embree_version);
    m.def("cuda_info", []() {
        const CudaInfo info = cuda_info();
        nb::dict d;
        d["compiled"] = info.compiled;
        d["available"] = info.available;
        d["reason"] = info.reason;
        d["name"] = info.name;
        d["memory_bytes"] = info.memory_bytes;
        d["compute_capability"] = info.compute_capability;
        d["driver_version"] = info.driver_version;
        return d;
    });
    m.def("build_info", []() {
        nb::dict d;
        d["embree_headers"] = bool(LANTERN_HAVE_EMBREE);
        d["embree_library"] = embree_library_path();
        d["backends"] = cuda_info().compiled ? std::vector<std::string>{"cpu", "cuda", "auto"}
                                             : std::vector<std::string>{"cpu", "auto"};
        d["integrators"] = std::vector<std::string>{"auto", "pt", "lt", "bdpt", "lvc", "cis"};
        return d;
    });
    nb::class_<Session>(m, "Session")
        .def("__init__", &init_session, nb::arg("scene"), nb::arg("settings"))
        .def("step", &step_session)
        .def("cancel", &Session::cancel)
        .def("update_camera", [](Session& s, const nb::dict& view) {
            SceneInput in = to_input(view);  // its film and camera
            nb::gil_scoped_release release;  // waits for a running step
            return s.update_camera(in);
        }, nb::arg("view"))
        .def("set_connection_map", [](Session& s, const nb::bytes& map) {
            // (N, M) per pixel, row-major (integrator/pixel_conn.h); empty: none
            const auto* p = static_cast<const uint8_t*>(map.data());
            std::vector<uint8_t> v(p, p + map.size());
            nb::gil_scoped_release release;  // waits for a running step
            return s.set_connection_map(v);
        }, nb::arg("map"))
        .def("update_materials", [](Session& s, const nb::dict& materials) {
            SceneInput in = to_input(materials);  // its materials and textures
            nb::gil_scoped_release release;
            return s.update_materials(in);
        }, nb::arg("materials"))
        .def("move_instance", [](Session& s, int k, const std::vector<float>& m) {
            // m: 16 floats, row-major object-to-world relative to the exported positions
            if (m.size() != 16) throw std::invalid_argument("move_instance needs a 4x4 matrix");
            if (m[12] != 0.0f || m[13] != 0.0f || m[14] != 0.0f || m[15] != 1.0f)
                throw std::invalid_argument("move_instance: the matrix's last row must be 0 0 0 1");
            const Transform t = transform_from_rows(m.data());
            nb::gil_scoped_release release;
            return s.move_instance(k, t);
        }, nb::arg("index"), nb::arg("matrix"))
        .def("image", [](const Session& s) {
            // the snapshot itself becomes the array's memory (no second copy)
            auto* img = new std::vector<float>();
            {
                nb::gil_scoped_release release;  // it may wait for a step to publish
                *img = s.image();
            }
            nb::capsule owner(img, [](void* p) noexcept {
                delete static_cast<std::vector<float>*>(p);
            });
            return nb::ndarray<nb::numpy, float, nb::ndim<3>>(
                img->data(), {size_t(s.height()), size_t(s.width()), 3}, owner);
        })
        .def_prop_ro("spp", &Session::spp)
        .def("pixel_samples", [](const Session& s) {  // adaptive sampling: (H, W) int32
            auto* n = new std::vector<int32_t>(s.pixel_samples());
            nb::capsule owner(n, [](void* p) noexcept {
                delete static_cast<std::vector<int32_t>*>(p);
            });
            return nb::ndarray<nb::numpy, int32_t, nb::ndim<2>>(
                n->data(), {size_t(s.height()), size_t(s.width())}, owner);
        })
        .def_prop_ro("active_pixels", &Session::active_pixels)
        .def_prop_ro("converged", &Session::converged)
        .def_prop_ro("noise_error", &Session::noise_error)
        .def_prop_ro("backend", &Session::backend_name)
        .def_prop_ro("device", &Session::device_name)
        .def("warnings", [](const Session& s) { return s.warnings(); })
        .def("stats", [](const Session& s) {
            const SessionStats& st = s.stats();
            nb::dict d;
            d["iterations"] = st.iterations;
            d["spp"] = s.spp();
            d["backend"] = s.backend_name();
            d["device"] = s.device_name();
            d["device_memory_peak"] = st.device_memory_peak;
            d["device_memory_used"] = st.device_memory_used;
            d["accel_bottom_builds"] = st.accel_bottom_builds;
            d["instance_moves"] = st.instance_moves;
            d["embree"] = embree_version();
            d["rays_camera"] = st.rays_camera;
            d["rays_indirect"] = st.rays_indirect;
            d["rays_shadow"] = st.rays_shadow;
            d["rays_light"] = st.rays_light;
            d["rays_connection"] = st.rays_connection;
            d["rays_light_tracing"] = st.rays_light_tracing;
            d["cis_candidates"] = st.cis_candidates;
            if (st.mean_connections >= 0.0) {
                d["mean_connections"] = st.mean_connections;
                d["connection_choices"] = st.connection_choices;
            }
            d["rays_total"] = st.rays_camera + st.rays_indirect + st.rays_shadow + st.rays_light +
                              st.rays_connection + st.rays_light_tracing;
            if (st.auto_choice >= 0) {  // integrator "auto" (integrator/allocation.h)
                static const char* const kChoice[] = {"pilot", "pt", "cis"};
                d["auto_choice"] = kChoice[std::min(st.auto_choice, 2)];
                d["auto_cis_over_pt"] = st.auto_cis_over_pt;
                d["auto_pt_tail"] = st.auto_pt_tail;
                d["auto_pt_iterations"] = st.auto_pt_iterations;
                d["auto_cis_iterations"] = st.auto_cis_iterations;
                d["auto_cis_vertices"] = st.auto_cis_vertices;
            }
            d["cache_vertices"] = st.cache_vertices;
            d["sorted_bounces"] = st.sorted_bounces;
            d["unsorted_bounces"] = st.unsorted_bounces;
            d["time_light_pass"] = st.time_light_pass;
            d["time_camera_pass"] = st.time_camera_pass;
            d["time_sort"] = st.time_sort;
            d["time_cache"] = st.time_cache;
            d["time_splat"] = st.time_splat;
            d["nonfinite_dropped"] = st.nonfinite_dropped;
            d["time_build"] = st.time_build;
            d["time_generate"] = st.time_generate;
            d["time_trace"] = st.time_trace;
            d["time_shade"] = st.time_shade;
            d["time_shadow"] = st.time_shadow;
            d["time_film"] = st.time_film;
            d["time_total"] = st.time_total;
            return d;
        });
}
