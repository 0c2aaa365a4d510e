// The host scene: owns every buffer a render needs and hands stages a SceneView of them.
// Built from a SceneInput (what the Python side or a test describes), it converts Blender's
// quantities to radiance, drops what cannot render (non-finite values, zero-area emitters)
// with a warning, and builds the light-selection distribution.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "accel/tlas_build.h"
#include "scene/material_program.h"
#include "scene/envmap_build.h"
#include "scene/light_tree_build.h"
#include "scene/medium_input.h"
#include "scene/scene_view.h"

namespace lantern {

struct MeshInput {
    std::string name;
    std::vector<float> positions;      // 3 per vertex, world space
    std::vector<float> normals;        // 3 per vertex or empty
    std::vector<float> uvs;            // 2 per vertex or empty
    std::vector<float> tangents;       // 4 per vertex (xyz, bitangent sign) or empty
    std::vector<uint32_t> indices;     // 3 per triangle
    std::vector<uint32_t> material_ids;  // 1 per triangle
    std::vector<float> attributes;     // SceneInput::num_attribute_channels x 3 per vertex, or empty
    bool visible_camera = true;
    bool cast_shadow = true;
    bool shadow_catcher = false;       // TriangleFlags kShadowCatcher (pt)
    uint8_t rays = kRayKindsAll;       // RayKinds that see it (SceneView::tri_rays, pt)
    // Cycles' Shadow Terminator Geometry Offset (SceneView::tri_terminator), 0..1; 0: off
    float terminator = 0.0f;
    // flat shaded (Blender's Face normals domain): each triangle by its own normal, as Cycles
    // shades a face without smooth shading; the normals (the face's) are not read
    bool flat = false;
    // light linking (pt; scene/light_linking_build.cpp): its receiver set, and the receiver
    // sets its emission lights (bit s: set s)
    int32_t light_set = 0;
    uint64_t emitter_receivers = kAllReceivers;
    // shadow linking: its blocker set, and the blocker sets that shadow its emission
    int32_t shadow_set = 0;
    uint64_t emitter_blockers = kAllReceivers;
    // motion blur (scene/motion_build.cpp): object-to-world at the shutter's steps, 16 floats
    // (row-major 4x4) each, and motion_base, the one positions were exported with; empty: still
    std::vector<float> motion;
    float motion_base[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    // deformation blur: the positions at the shutter's steps (S x positions.size()), placed as
    // the positions are (scene/deform_build.cpp, docs/motion_blur.md)
    std::vector<float> deform;
};

// Strands (docs/curves.md, addon/export/curves.py): points, a radius per point, strand s is
// points offsets[s] .. offsets[s + 1] - 1, a material per strand; round linear segments.
struct CurveInput {
    std::string name;
    std::vector<float> points;        // 3 per point, world space
    std::vector<float> radius;        // 1 per point
    std::vector<int32_t> offsets;     // strands + 1, from 0, increasing
    std::vector<uint32_t> material_ids;  // 1 per strand
    // motion blur (docs/motion_blur.md "Strands"): the points (S x points.size()) and optionally
    // the radii (S x radius.size()) at the shutter's S >= 2 steps, placed as `points` are (world
    // space where the set has no `motion`); empty: still
    std::vector<float> deform;
    std::vector<float> deform_radius;
    // its object's motion ("Strands of a turning object", scene/motion_build.cpp): as a mesh's,
    // object-to-world at the steps (16 floats each) and motion_base, the matrix the points (and
    // deform) were exported with; empty: the points do not move with an object's matrix
    std::vector<float> motion;
    float motion_base[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    bool visible_camera = true;
    bool cast_shadow = true;
    uint8_t rays = kRayKindsAll;  // its object's RayKinds (as MeshInput's; SceneView::tri_rays)
    // light and shadow linking (as MeshInput's): its object's receiver and blocker sets
    int32_t light_set = 0;
    int32_t shadow_set = 0;
};

struct MaterialInput {
    std::string name;
    std::string type = "diffuse";  // diffuse, conductor, dielectric, principled, mix, translucent
    Vec3 base_color{0.8f, 0.8f, 0.8f};
    Vec3 emission{0.0f, 0.0f, 0.0f};
    float roughness = 0.5f;
    float diffuse_roughness = 0.0f;  // Oren-Nayar (EON) of the diffuse base; 0: Lambert
    float anisotropy = 0.0f;         // Blender's Anisotropic, [0, 1]
    float anisotropic_rotation = 0.0f;  // turns
    std::string tangent = "triangle";   // "uv" (Tangent node, UV) or "triangle" (Cycles' dPdu)
    float ior = 1.5f;
    Vec3 specular_tint{1.0f, 1.0f, 1.0f};
    // conductor: exact Fresnel of the complex index eta + i k (then base_color scales it, as
    // Mitsuba's specular_reflectance) instead of the F82-tint model
    bool complex_fresnel = false;
    std::string distribution = "ggx";  // conductor: "ggx" or "beckmann"
    // dielectric: base_color tints reflection as well as transmission (Blender's Glass BSDF
    // Color; Mitsuba's specular_transmittance tints transmission only)
    bool tint_reflection = false;
    Vec3 eta{0.0f, 0.0f, 0.0f};
    Vec3 k{1.0f, 1.0f, 1.0f};
    // principled
    float metallic = 0.0f;
    float transmission = 0.0f;
    float specular_level = 0.5f;  // Blender's Specular IOR Level (0.5: the IOR as given)
    bool multiscatter = true;     // GGX energy compensation (Blender's Multiscatter GGX)
    float coat_weight = 0.0f, coat_roughness = 0.03f, coat_ior = 1.5f;
    Vec3 coat_tint{1.0f, 1.0f, 1.0f};
    float sheen_weight = 0.0f, sheen_roughness = 0.5f;
    float thin_film_thickness = 0.0f, thin_film_ior = 1.33f;  // nm (0: none); the film's index
    Vec3 sheen_tint{1.0f, 1.0f, 1.0f};
    // principled subsurface (integrator/pt_sss.h): Subsurface Weight, Radius x Scale (metres),
    // IOR, Anisotropy; method "random_walk" or "random_walk_skin"
    float subsurface_weight = 0.0f;
    Vec3 subsurface_radius{0.0f, 0.0f, 0.0f};
    float subsurface_ior = 1.4f, subsurface_anisotropy = 0.0f;
    std::string subsurface_method = "random_walk";
    // textures: indices into SceneInput::textures, -1 for none
    int tex_base_color = -1, tex_roughness = -1, tex_metallic = -1, tex_alpha = -1,
        tex_normal = -1, tex_emission = -1;  // emission texture: radiance = texel x emission
    float normal_strength = 1.0f;
    // principled coat's own normal map (Coat Normal), -1: none; the coat then follows the
    // smooth interpolated normal wherever the base's Normal is mapped (Cycles)
    int tex_coat_normal = -1;
    float coat_normal_strength = 1.0f;
    float alpha = 1.0f;  // coverage: 0 lets every ray pass (Blender's Alpha)
    bool holdout = false;  // Holdout shader or holdout object: camera paths end here
    // mix: leaf materials (indices, not mixes) and weights; tex_mix: factor of two leaves
    std::vector<int> mix_children;
    std::vector<float> mix_weights;
    int tex_mix = -1;
    // node-graph programs: SceneInput::programs rows program_first .. + program_count
    int program_first = 0, program_count = 0;
    // media (docs/volumes.md): SceneInput::media index of the medium inside the mesh, -1 none;
    // volume_only: no surface (a volume boundary that pt passes through)
    int medium = -1;
    bool volume_only = false;
    // hair (type "hair", Principled Hair, bsdf/hair.h; scene/hair_build.cpp): the absorption
    // by parametrisation "melanin" (melanin, melanin_redness, hair_tint), "color" (base_color,
    // Direct Coloring) or "absorption" (absorption); roughness, radial roughness, coat, ior,
    // offset (radians)
    std::string hair_parametrization = "color";
    float melanin = 0.8f, melanin_redness = 1.0f;
    Vec3 hair_tint{1.0f, 1.0f, 1.0f};
    Vec3 absorption{0.245531f, 0.52f, 1.365f};
    float radial_roughness = 0.3f, hair_coat = 0.0f, hair_offset = 0.034906585f;
    // a Volume object's: SceneInput::grids index of the density its medium's coefficients are
    // per unit of (scene/medium_grid.h), -1 none
    int density_grid = -1;
    // its fire (scene/medium_fire.h): SceneInput::grids indices of the temperature (blackbody per
    // point) and flame (emission per point) grids, -1 none
    int temperature_grid = -1, flame_grid = -1;
    // its colour grid (Principled Volume's Color Attribute, 3 channels), -1 none
    int color_grid = -1;
};

// An image texture with its sampling settings. Texels: width x height x 4 (RGBA), rows bottom
// to top; 8-bit ones in `bytes` (format srgb or linear), float ones in `floats`.
struct TextureInput {
    std::string name;
    int width = 0, height = 0;
    std::string format = "srgb";  // srgb | linear (8-bit) | float
    std::string wrap = "repeat";  // repeat | extend | clip | mirror
    std::string interpolation = "linear";  // linear | closest
    std::string output = "color";  // color | alpha | red | green | blue: what scalar inputs read
    float uv[6] = {1, 0, 0, 0, 1, 0};
    std::vector<uint8_t> bytes;
    std::vector<float> floats;
};

struct LightInput {
    std::string name;        // the object's name, for warnings (may be empty)
    std::string type;        // point, spot, area, sun
    float to_world[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // row-major
    Vec3 position;
    Vec3 direction{0, 0, -1};
    Vec3 power;              // point/spot/area: W (color * energy)
    Vec3 strength;           // sun: W/m^2
    float radius = 0.0f;
    float spot_size = 0.785398f;
    float spot_blend = 0.15f;
    std::string shape = "square";
    float size_x = 1.0f, size_y = 1.0f;
    float angle = 0.0f;
    bool soft_falloff = true;
    bool visible_camera = false;
    uint8_t rays = kRayKindsAll;  // RayKinds that see the lamp (Diffuse, Glossy, ...: pt)
    bool cast_shadow = true;      // false: Blender's Cast Shadow off (pt: kLampNoShadow)
    // sun: the world's own (the Sky Texture's disc, lantern/scene.py to_native): seen by the
    // camera as the world is (world_visible_camera, not through transparent film), hidden
    // from the scatterings the world is hidden from (world_rays, pt)
    bool of_world = false;
    uint64_t receivers = kAllReceivers;  // light linking: the receiver sets it lights (pt)
    uint64_t blockers = kAllReceivers;   // shadow linking: the blocker sets that shadow it (pt)
};

struct SceneInput {
    int width = 64, height = 64;
    float filter_width = 1.5f;
    bool orthographic = false;
    bool panoramic = false;  // equirectangular: pano_range = longitude min, max, latitude min, max
    float pano_range[4] = {-kPi, kPi, -0.5f * kPi, 0.5f * kPi};
    float camera_to_world[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    float screen[4] = {-0.5f, 0.5f, -0.5f, 0.5f};
    float clip_start = 0.1f, clip_end = 1000.0f;
    // depth of field (CameraView): lens radius in metres (0: a pinhole), focus distance
    float lens_radius = 0.0f, focus_distance = 10.0f;
    int aperture_blades = 0;
    float aperture_rotation = 0.0f, aperture_ratio = 1.0f;
    Vec3 world_color;
    EnvMapInput world_map;            // width 0: none (the world is world_color)
    bool world_visible_camera = true; // false: camera rays see black (the world still lights)
    bool film_transparent = false;    // Blender's transparent film: the world is not drawn
    int catcher_mode = 0;             // SceneView::catcher_mode (lantern/film.py)
    unsigned world_rays = 15;         // SceneView::world_rays (WorldRays)
    std::vector<MaterialInput> materials;
    std::vector<TextureInput> textures;
    std::vector<MeshInput> meshes;
    std::vector<LightInput> lights;
    std::vector<CurveInput> curves;  // strands (scene/scene_curves.cpp)
    // compiled node graphs (scene/material_program.h, docs/scene_format.md "node programs"):
    // programs 6 uint32 each (first_instr, num_instr, first_const, num_const, target, result),
    // program_code 4 uint32 per instruction (op | mode << 8 | flags << 16 | dim << 24,
    // in | out << 16, aux, aux2), program_consts the constants and tables
    std::vector<uint32_t> programs, program_code;
    std::vector<float> program_consts;
    int num_attribute_channels = 0;  // per-vertex attribute channels of every mesh
    std::vector<MediumInput> media;  // homogeneous media (scene/medium_build.cpp)
    std::vector<GridInput> grids;    // Volume objects' density grids (scene/medium_grid_build.cpp)
    int world_medium = -1;           // the world's Volume: an index into media, -1 none
    std::vector<float> camera_motion;  // camera_to_world at the shutter's steps (16 each), or empty
};

class HostScene {
public:
    // Throws std::invalid_argument with a clear message for input that cannot be rendered.
    // soft_light_paths: light paths start on soft-falloff point/spot lights
    // (integrator/soft_light_path.h); false for a GPU session, whose light shade kernel leaves
    // that route out (its shadow ray's traversal took the kernel's stack over 2 KB), so such
    // lights are camera-side there
    explicit HostScene(const SceneInput& in, bool soft_light_paths = true);
    // not copyable: each material points at its tables in this scene (point_material_tables)
    HostScene(const HostScene&) = delete;
    HostScene& operator=(const HostScene&) = delete;
    const SceneView& view() const { return view_; }
    // A new camera and film size (in's film and camera fields only); the rest stays.
    void set_camera(const SceneInput& in);
    // New materials and textures (in's) in place; false, with nothing changed, when the
    // triangles, lights or acceleration structure would change too (emission, alpha,
    // textures, the number of materials): build a new scene then.
    bool update_materials(const SceneInput& in);
    const std::vector<std::string>& warnings() const { return warnings_; }
    // kHairReverse on every hair material (kept through update_materials): the session sets
    // it for the integrators that read the hair lobe's reverse pdf (not pt: it costs pt 18 %)
    void set_hair_reverse(bool on);
    // Where each of in.meshes lies in the scene's arrays (the instances of two-level accels).
    const std::vector<MeshRange>& mesh_ranges() const { return mesh_ranges_; }
    // scene_instance.cpp: mesh k placed by to_world relative to the positions it was given
    // with (its world-space positions, normals and tangents written again, in place). False,
    // nothing changed, where the move reaches further: k out of range, an emitting mesh (the
    // lights would change), a singular, mirroring or non-finite transform, or a vertex leaving
    // the scene's bounding sphere (distant lights' disk) or the ray queries' range.
    bool move_mesh(int k, const Transform& to_world);
    int num_triangles() const { return int(indices_.size() / 3); }
    // view() with every array it points into copied elsewhere (a GPU's memory): copy(host,
    // bytes) receives each array (host null or bytes 0 when empty) and returns the copy's address.
    SceneView copied_view(const std::function<const void*(const void*, size_t)>& copy) const;

private:
    void point_material_tables();
    void set_mix_leaves(const SceneInput& in);
    void add_textures(const SceneInput& in);
    void finish_emission_textures();
    void add_meshes(const SceneInput& in);
    void add_lights(const SceneInput& in);
    void build_light_linking(const SceneInput& in);  // light_linking_build.cpp
    void drop_redundant_shadow_links();              // ... after add_curve_prims
    void build_lamp_rays(const SceneInput& in);      // lamp_rays_build.cpp
    void build_filter(float width);
    void finish_view(const SceneInput& in);
    void add_programs(const SceneInput& in);  // scene/material_program.cpp
    void fill_lobe_tables();
    void build_media(const SceneInput& in);  // scene/medium_build.cpp
    int32_t density_program(size_t material) const;  // scene/medium_hetero_build.cpp
    int32_t program_of(size_t material, int32_t target) const;  // (the same)
    void build_hetero(int32_t med, size_t material, const std::string& name);
    void build_grids(const SceneInput& in);   // scene/medium_grid_build.cpp
    void build_grid_medium(int32_t med, const std::string& name);      // scene/medium_grid_build.cpp
    void grid_fire(Medium& m, const MaterialInput& mi, const MediumInput& src);  // the same
    void build_majorant_grid(int32_t med);    // scene/medium_majorant_build.cpp
    // a colour grid's bound on m's extinction per unit density over a box of g's index space
    float program_density_bound(int32_t med, const DensityGrid& g, float lx, float ly, float lz,
                                float hx, float hy, float hz) const;  // medium_grid_build.cpp
    Vec3 color_bound(const Medium& m, const DensityGrid& g, const float lo[3],
                     const float hi[3]) const;  // scene/medium_grid_build.cpp
    // scene/medium_color_build.cpp: colour programs (kTargetVolumeColor, ...EmissionColor)
    void volume_color_programs(Medium& m, const MediumInput& src, size_t material);
    // the colour program's extinction per unit density over a world box (ok: it has a bound)
    Vec3 color_prog_unit(int32_t med, Vec3 lo, Vec3 hi, bool* ok) const;
    Vec3 color_prog_fallback(int32_t med, Vec3 lo, Vec3 hi, const std::string& name);
    float mesh_color_majorant(int32_t med, Vec3 lo, Vec3 hi, const std::string& name);
    void grid_box_world(const DensityGrid& g, const float lo[3], const float hi[3], Vec3* wlo,
                        Vec3* whi) const;
    Vec3 color_prog_whole_{};  // the colour program's part over the whole grid (a fallback)
    void nest_media(const SceneInput& in, const Medium* world);  // scene/medium_build.cpp
    void set_shadow_media(const SceneInput& in);  // scene/medium_build.cpp
    void inset_volume_boundaries();  // scene/medium_inset.cpp
    bool boundary_meets_a_face(const MeshRange& r, Vec3 lo, Vec3 hi, float eps,
                               size_t ntri) const;
    int32_t camera_medium_at(Vec3 p) const;
    void build_motion(const SceneInput& in);  // scene/motion_build.cpp
    void add_curves(const SceneInput& in);     // scene/scene_curves.cpp: segments, bounds
    void add_curve_prims(const SceneInput& in);  // ... and their per-primitive entries
    // scene/curve_motion.cpp: curves k's steps (0: still; a warning where they are unusable)
    int curve_input_steps(const CurveInput& c, const std::string& who);

    std::vector<Vec3> positions_, normals_;
    std::vector<Vec2> uvs_;
    std::vector<float> tangents_;
    std::vector<Texture> textures_;
    size_t textures_in_count_ = 0;
    std::vector<Vec3> texture_mean_;  // mean decoded colour of each texture
    std::vector<uint8_t> texels_;
    std::vector<float> srgb_lut_;
    std::vector<uint32_t> indices_, tri_material_;
    std::vector<uint8_t> tri_flags_;
    std::vector<float> tri_terminator_;  // per triangle; empty: no mesh has a terminator offset
    std::vector<uint8_t> tri_rays_;  // SceneView::tri_rays: empty where every mesh is seen by all
    std::vector<int32_t> tri_light_, hittable_lights_, miss_lights_;
    std::vector<int32_t> lamp_input_;       // per light: its SceneInput::lights index, or -1
    std::vector<uint8_t> tri_light_set_;    // SceneView::tri_light_set (empty: no linking)
    std::vector<uint64_t> light_receivers_; // SceneView::light_receivers (empty: no linking)
    std::vector<uint8_t> light_rays_;       // SceneView::light_rays (empty: all see all)
    std::vector<uint8_t> tri_shadow_set_;   // SceneView::tri_shadow_set (empty: none)
    std::vector<uint64_t> light_blockers_;  // SceneView::light_blockers (empty: none)
    std::vector<Material> materials_;
    bool hair_reverse_ = false;  // set_hair_reverse
    bool soft_light_paths_ = true;  // the constructor's
    std::vector<MaterialTables> material_tables_;  // materials_[k].tables: the k-th
    std::vector<Light> lights_;
    std::vector<float> light_cdf_, nee_cdf_, emit_cdf_, filter_cdf_;
    std::vector<MaterialProgram> programs_;
    std::vector<NodeInstr> program_code_;
    std::vector<float> program_consts_, attributes_;
    std::vector<Medium> media_;               // SceneView::media
    std::vector<int32_t> material_medium_;    // SceneView::material_medium (empty: no media)
    std::vector<int32_t> light_medium_;       // SceneView::light_medium (empty: no media)
    std::vector<Transform> medium_maps_;      // SceneView::medium_maps (empty: none heterogeneous)
    std::vector<DensityGrid> grids_;          // SceneView::grids (empty: no Volume objects)
    std::vector<float> grid_voxels_;          // SceneView::grid_voxels
    std::vector<std::string> grid_names_;       // the grids' names (messages)
    std::vector<float> grid_index_to_world_;  // the grids' index-to-world maps (16 floats each)
    std::vector<MajorantGrid> majorant_grids_;  // SceneView::majorant_grids (media's bricks)
    std::vector<float> majorant_values_;        // SceneView::majorant_values
    int num_attribute_channels_ = 0;
    std::shared_ptr<const EnvMapStorage> env_ = std::make_shared<EnvMapStorage>();  // cached
    bool has_emitters_ = false;
    bool has_nee_lights_ = false;  // next-event estimation has a light to pick
    LightTreeStorage light_tree_;  // next-event estimation's light tree (scene/light_tree.h)
    bool light_tree_on_ = false;
    std::vector<std::string> warnings_;
    SceneView view_;
    std::vector<MeshRange> mesh_ranges_;
    struct MeshCopy {  // a moved mesh's arrays as given (move_mesh places them again)
        std::vector<Vec3> positions, normals;
        std::vector<float> tangents;
    };
    std::vector<std::unique_ptr<MeshCopy>> mesh_given_;  // per mesh, null until it moves
    std::vector<MotionStep> motion_steps_;      // SceneView::motion (motion blur)
    std::vector<ObjectMotion> motion_objects_;
    std::vector<int32_t> motion_media_;  // MotionView::medium_objects (empty: none moves)
    std::vector<CurveSeg> curve_segs_;          // SceneView::curves (strands)
    std::vector<uint32_t> curve_material_;      // per segment
    std::vector<uint8_t> curve_flags_;          // per segment: kVisibleCamera, kCastShadow
    std::vector<CurveSeg> curve_keys_;  // moving strands' steps (CurveKeys; scene/curve_motion.cpp)
    int32_t curve_steps_ = 0;
    std::vector<std::pair<int32_t, int32_t>> curve_ranges_;  // per CurveInput: first segment, count
    std::vector<CurveSetMotion> curve_sets_;  // CurveView::sets (moving with their objects)
    std::vector<DeformMesh> motion_deforms_;   // deformation blur (scene/deform_build.cpp)
    std::vector<Vec3> motion_corners_;
};

// scene/curve_motion.cpp: the segment from points i, i + 1 of c (steps: its motion steps) at
// step k of `shared` steps evenly spread over the shutter
CurveSeg curve_key(const CurveInput& c, int steps, int32_t i, int k, int shared);

// scene/hair_build.cpp: a "hair" MaterialInput into m (type kMaterialHair)
void set_hair_material(Material& m, const MaterialInput& mi);

Transform transform_from_rows(const float m[16]);

// Appends mesh m's attribute channels (zeros where it has none) to out (material_program.cpp).
void add_mesh_attributes(const MeshInput& m, size_t num_vertices, size_t channels,
                         std::vector<float>& out);

}  // namespace lantern
