// What stages see of a scene: plain structs and raw pointers into buffers the host Scene owns
// (on the GPU, device buffers). No containers, strings or virtual calls reach a stage.
#pragma once

#include "core/math.h"
#include "scene/curves.h"
#include "scene/envmap.h"
#include "scene/medium.h"
#include "scene/medium_grid.h"
#include "scene/medium_majorant.h"
#include "scene/motion.h"
#include "scene/texture.h"

namespace lantern {

// The type says which code path shades a material (the high 8 bits of the sort key, see
// material_key); bsdf/material.h dispatches on it.
enum MaterialType : uint32_t {
    kMaterialDiffuse = 0,     // Lambert, albedo base_color
    kMaterialConductor = 1,   // GGX metal: F82 (F0 base_color, tint specular_tint) or complex
                              // Fresnel (eta, k; base_color scales it)
    kMaterialDielectric = 2,  // GGX (or smooth) glass: ior, transmission tint base_color
    kMaterialPrincipled = 3,  // Blender's Principled BSDF as layers: bsdf/principled.h
    kMaterialMix = 4,         // Mix / Add Shader: weighted leaves (bsdf/material.h)
    kMaterialTranslucent = 5, // Translucent BSDF: Lambertian transmission, colour base_color
    kMaterialHair = 6,        // Principled Hair (Chiang): bsdf/hair_lobe.h reads its fields
    kMaterialTypeCount = 7,
};

constexpr int kMixLeaves = 4;  // leaves of one mix material (nested mixes are flattened)

constexpr int kPrincipledAlbedoN = 33;  // at cosines (k / 32)^2: dense where Fresnel rises
// Roughness rows of a material whose roughness a texture or node graph gives per hit: its
// tables at roughness j / (kRoughRows - 1), read by cubic interpolation at the hit's roughness
// (bsdf/multiscatter.h ms_rough)
constexpr int kRoughRows = 33;
// The LTC sheen's fit (bsdf/sheen.h): a, b and R at cosines i / (kSheenLtcN - 1)
constexpr int kSheenLtcN = 32;

// A material's albedo tables by cosine (bsdf/multiscatter.h ms_table), made when the scene is
// built. Resolving a hit's material (bsdf/material.h material_at) never changes them, so they
// live apart, one per material in SceneView::material_tables, and the resolved copies a GPU
// thread keeps on its stack (MaterialScratch) hold only the pointer.
struct MaterialTables {
    float spec_albedo[kPrincipledAlbedoN];  // principled specular layer (max channel)
    float ms_e[kPrincipledAlbedoN];         // the white GGX lobe of the material's roughness
    float coat_albedo[kPrincipledAlbedoN];  // principled coat
    float sheen_ltc[3 * kSheenLtcN];        // the sheen's fit at its roughness (bsdf/sheen.h)
    float e_avg;                            // E_avg of ms_e (a roughness row's)
    // per-hit roughness (a texture or node graph on Roughness): this + rough_rows is the first
    // of kRoughRows rows (ms_e, e_avg and spec_albedo at roughness j / (kRoughRows - 1)),
    // which the lobes read at the hit's roughness; 0: none (these are the roughness's own).
    // Here, not in Material, so that a resolved copy on a GPU thread's stack stays its size.
    int32_t rough_rows;
    Vec3 spec_favg;  // the principled specular layer's average Fresnel: fms_spec per hit
};

struct MaterialInputs;  // bsdf/material.h: what resolving a leaf at a hit changes

struct Material {
    Vec3 base_color;
    Vec3 emission;       // radiance, both sides
    uint32_t type;       // MaterialType
    float roughness;     // Blender's roughness (alpha = roughness^2)
    float anisotropy;    // Blender's Anisotropic in [0, 1]: GGX alpha_x / alpha_y (microfacet.h)
    float aniso_rotation;   // of the tangent about the normal, in turns
    uint32_t aniso_uv_tangent;  // 1: tangent from the uv map (Tangent node, UV), 0: the
                                // triangle's p0 - p2 (Cycles' dPdu when Tangent is unlinked)
    float ior;           // dielectric: n_inside / n_outside
    Vec3 specular_tint;  // conductor: F82 tint; principled: specular tint (and the metal's F82)
    Vec3 eta, k;         // conductor with kFresnelComplex: complex index eta + i k per channel
    uint32_t fresnel;    // conductor: ConductorFresnelMode
    uint32_t beckmann;   // conductor: Beckmann distribution instead of GGX (Mitsuba scenes)
    float diffuse_roughness;  // diffuse and principled base: Oren-Nayar (EON) roughness, 0: Lambert
    // principled only
    float metallic;
    float transmission;
    float spec_eta;      // the specular layer's IOR after Blender's Specular IOR Level
    float film_thickness;  // Thin Film Thickness (nm) on the specular layer, 0: none
    float film_ior;        // Thin Film IOR
    // GGX multiple-scattering compensation (conductor, principled): bsdf/multiscatter.h
    uint32_t multiscatter;  // 1: compensate (Blender's "Multiscatter GGX", the default)
    Vec3 fms_metal;      // Kulla-Conty multiple-scattering Fresnel of the metal lobe
    Vec3 fms_spec;       // ... of the principled specular layer
    // the albedo tables (specular layer, white GGX, coat, sheen): SceneView::material_tables
    // [material id], or for a mix leaf the leaf's; a resolved copy keeps its material's
    const MaterialTables* tables;
    // principled coat: a dielectric GGX layer over everything else
    float coat_weight, coat_roughness, coat_ior;
    Vec3 coat_tint;
    // kCoatNormal: the coat has its own shading normal (Principled Coat Normal): the normal
    // map tex_coat_normal of coat_normal_strength on the interpolated normal, or (-1) the
    // interpolated normal itself, as Cycles' coat when only the base Normal is mapped
    int32_t tex_coat_normal;
    float coat_normal_strength;
    // principled sheen: the top layer (bsdf/sheen.h)
    float sheen_weight, sheen_roughness;
    Vec3 sheen_tint;
    // textured inputs (bsdf/material.h material_at): bits of MaterialTextureBits say which
    // tex_* index is used; zero (the default) means a constant material that is never copied
    uint32_t tex_flags;
    int32_t tex_base_color, tex_roughness, tex_metallic, tex_alpha, tex_normal, tex_emission;
    Vec3 emission_scale;    // kTexEmission: radiance = texture colour x this (emission: the mean)
    float normal_strength;  // Blender's Normal Map strength
    float transparency;     // 1 - alpha: the share of rays that pass the surface untouched
    Vec3 metal_favg0, metal_favg1;  // the metal lobe's average Fresnel at F0 = 0 and 1, and
    float e_avg;                    // E_avg: fms_metal for a textured base colour
    // mix (kMaterialMix): leaf materials (never mixes) by index with constant weights, or for
    // two leaves weights (1 - t, t) from the factor texture tex_mix (kTexMix); material_at
    // points mix_leaf at the scene's leaves
    int32_t mix_count;
    int32_t mix_child[kMixLeaves];
    float mix_weight[kMixLeaves];
    int32_t tex_mix;
    const Material* mix_leaf[kMixLeaves];
    // a resolved mix: its textured leaves' resolved inputs (MaterialScratch::leaf), which
    // mix_leaf_at applies to the scene's leaf where resolved is set; null: the leaves as they are
    const MaterialInputs* mix_inputs;
    // kTexProgram: the compiled node graph, programs prog_first .. + prog_count of
    // SceneView::programs, one per input it drives (scene/material_program.h)
    int32_t prog_first, prog_count;
    uint32_t holdout;  // 1: a holdout (TriangleFlags kHoldout on its triangles)
    // principled subsurface (random walk, integrator/pt_sss.h): the share `subsurface` of the
    // diffuse base that scatters inside the mesh (0: none; the base keeps 1 - subsurface),
    // mean free paths ss_radius (Radius x Scale, metres), the entry's IOR, the walk's
    // Henyey-Greenstein anisotropy; ss_skin 1: Random Walk (Skin)
    float subsurface;
    Vec3 ss_radius;
    float ss_ior, ss_anisotropy;
    uint32_t ss_skin;
};

enum MaterialTextureBits : uint32_t {
    kTexBaseColor = 1u,
    kTexRoughness = 2u,
    kTexMetallic = 4u,
    kTexAlpha = 8u,      // alpha from a texture (constant alpha: transparency alone)
    kTexNormal = 16u,
    kTexMix = 32u,       // a mix's factor texture
    kTexEmission = 128u, // emission colour (mesh lights: lights.h triangle_emission)
    kCoatNormal = 256u,  // the coat's own normal (SurfaceHit::coat_n; bsdf/principled.h)
    kMixResolve = 64u,   // every mix: material_at must point it at its leaves
    kTexProgram = 512u,  // node-graph programs drive some inputs (scene/material_program.h)
    kTexBump = 1024u,    // a bump program bends the shading normal (program_bump; not resolved)
    kAlbedoBase = 2048u, // base_color is an albedo alone (no metal or glass reads it): above 1 kept
    kTintReflection = 4096u,  // dielectric: base_color tints reflection too (not resolved)
    kHairReverse = 8192u,     // hair: its lobe computes the reverse pdf (bsdf/hair_lobe.h): set
                              // where an integrator with light paths may render (HostScene)
    kHairTube = 16384u,       // hair as a mix's leaf: the tube's surface measure, not the fiber's
                              // (bsdf/hair_lobe.h, integrator/bdpt_curve.h; set_mix_leaves)
    kTexShading = kTexBaseColor | kTexRoughness | kTexMetallic | kTexEmission |
                  kTexProgram,                                   // resolved per hit
    kMaterialResolve = kTexShading | kTexMix | kMixResolve,      // material_at copies
};

// How a conductor computes its Fresnel term (bsdf/material.h): Blender's F82-tint with F0 =
// base_color, or the exact complex-IOR one (Mitsuba's conductor) times base_color.
enum ConductorFresnelMode : uint32_t {
    kFresnelF82Tint = 0,
    kFresnelComplex = 1,
};

// Sort key of the paper: high 8 bits the type, low 24 the material id.
LANTERN_HD inline uint32_t material_key(uint32_t type, uint32_t id) {
    return (type << 24) | (id & 0xFFFFFFu);
}

enum LightType : int32_t {
    kLightPoint = 0,   // sphere of `radius` (0: a true point), intensity-based
    kLightSpot = 1,
    kLightArea = 2,
    kLightSun = 3,
    kLightTriangle = 4,  // one emissive mesh triangle
    kLightWorld = 5,     // the background: SceneView::env, or the constant radiance
};

enum AreaShape : int32_t { kShapeRectangle = 0, kShapeEllipse = 1 };

struct Light {
    int32_t type;
    int32_t shape;          // area lights
    int32_t triangle;       // kLightTriangle: triangle index
    int32_t visible_camera;
    int32_t soft_falloff;   // point/spot: a disk facing the shaded point (Blender's default),
                            // else a sphere
    int32_t of_world;       // sun: part of the world (LightInput::of_world): world_rays apply
    Transform frame;        // area/spot: axes x, y and -z = emission direction; origin = centre
    Vec3 position;          // point/spot centre
    Vec3 direction;         // sun: direction the light travels; spot: cone axis
    Vec3 radiance;          // area/sphere/sun/world/triangle: emitted radiance
    Vec3 intensity;         // point/spot with radius 0: W/sr
    float radius;           // point/spot sphere radius
    float half_x, half_y;   // area: half extents
    float area;             // area of the emitting surface (area, triangle)
    float cos_half_spot;    // spot: cosine of half the cone angle
    float spot_smooth;      // spot: (1 - cos_half_spot) * blend
    float cos_sun;          // sun: cosine of half the angle (1: delta)
    float pick_pdf;         // probability of starting a light tracer's (lt) path on it
    float nee_pdf;          // probability of next-event estimation choosing it (no light tree);
                            // 0 for a constant world, which BSDF sampling finds better alone
    float emit_pick_pdf;    // probability of starting a light sub-path on it (0: camera-side only)
    // light tree (scene/light_tree.h): the leaf node of a local light (-1: distant or no tree)
    // and the intensity that ranks it (W/sr; distant lights: the irradiance, W/m^2)
    int32_t tree_leaf;
    float tree_energy;
};

// A node of the light tree in depth-first order: the first child follows its parent, `right`
// is the second (-1 at a leaf, which holds one light). Bounds of the lights' extent, their
// total intensity, and the cone of their normals (axis, theta_o) widened by the emission
// spread theta_e, both as cosines [Conty Estevez & Kulla 2018].
struct LightTreeNode {
    Vec3 lo;
    float energy;
    Vec3 hi;
    float cos_o;  // cos theta_o
    Vec3 axis;
    float cos_e;  // cos theta_e
    int32_t right;
    int32_t light;
};

// kAlphaTested: the material has alpha < 1 (constant or textured): hits go through
// scene/alpha.h's stochastic test
// kHoldout: the material is a holdout (Holdout shader, holdout object): camera paths that
// reach it end there, adding nothing (the film's alpha is 0 there: lantern/film.py)
// kShadowCatcher: a shadow catcher object (pt only; SceneView::catcher_mode says how pt treats it)
// kVolumeBoundary: a material with a volume and no surface: pt passes through it, entering or
// leaving its medium (integrator/pt_volume.h)
enum TriangleFlags : uint8_t { kVisibleCamera = 1, kCastShadow = 2, kAlphaTested = 4,
                               kHoldout = 8, kShadowCatcher = 16, kVolumeBoundary = 32 };

// SceneView::catcher_mode, the three renders of a scene with shadow catchers (lantern/film.py):
// kCatcherMatte (the beauty): camera rays that reach a catcher end there, as at a holdout;
// kCatcherObject: only paths whose camera ray reaches a catcher count, in the full scene;
// kCatcherPass: the same, and after the catcher every other surface is passed through (the
// render also casts no shadow from them), so the catcher is lit as if it were alone.
enum CatcherMode : int32_t { kCatcherMatte = 0, kCatcherObject = 1, kCatcherPass = 2 };

// SceneView::world_rays: the scatterings whose rays see the world (Cycles' world ray
// visibility; camera rays: the world light's visible_camera). Transmission is any scattering
// through the surface; diffuse and glossy are reflections (integrator/pt.h pt_world_sees);
// volume: a medium vertex's phase sample and next-event estimation (Cycles'
// SHADER_EXCLUDE_SCATTER; integrator/pt_volume.h).
// SceneView::tri_rays: the scatterings whose rays see a triangle's object (Cycles' object ray
// visibility Diffuse, Glossy, Transmission, Volume Scatter; pt: integrator/pt_ray_visibility.h)
enum RayKinds : uint8_t { kRayDiffuse = 1, kRayGlossy = 2, kRayTransmission = 4,
                          kRayVolumeScatter = 8, kRayKindsAll = 15 };
// SceneView::light_rays' bit beside the RayKinds: the lamp casts no shadow (Blender's light
// Cast Shadow off, Cycles' SHADER_CAST_SHADOW cleared): pt's next-event estimation of it traces
// no shadow ray (integrator/pt_ray_visibility.h pt_lamp_unshadowed)
constexpr uint8_t kLampNoShadow = 16;

// Light linking: every receiver set (SceneView::light_receivers' bits)
constexpr uint64_t kAllReceivers = ~uint64_t(0);

enum WorldRays : uint32_t { kWorldDiffuse = 1, kWorldGlossy = 2, kWorldTransmission = 4,
                            kWorldVolume = 8, kWorldRaysAll = 15 };

struct CameraView {
    int32_t orthographic;
    int32_t panoramic = 0;  // 1: equirectangular (integrator/camera.h), longitudes and
    float pano_range[4] = {-kPi, kPi, -0.5f * kPi, 0.5f * kPi};  // latitudes min, max
    int32_t width, height;
    Transform to_world;     // rigid; looks down local -Z
    float screen[4];        // xmin, xmax, ymin, ymax on the z = -1 plane (or metres, ortho)
    float clip_start, clip_end;
    const float* filter_cdf;  // inverted CDF of the 1D pixel filter, filter_table_size entries
    int32_t filter_table_size;
    float filter_width;
    // depth of field (integrator/camera.h): a thin lens of this radius (0: a pinhole) in the
    // camera's z = 0 plane, focused on the plane focus_distance in front of it; the aperture
    // is a disk or (blades >= 3) a regular polygon turned by blade_rotation, squeezed in x
    // by 1 / aperture_ratio (Blender's anamorphic bokeh)
    float lens_radius = 0.0f;
    float focus_distance = 10.0f;
    int32_t blades = 0;
    float blade_rotation = 0.0f;
    float inv_aperture_ratio = 1.0f;
};

// What a scene's materials need at a hit, over all of them (HostScene::finish_view), so that a
// scene whose materials need none of it skips the per-hit checks and loads: a diffuse-only
// scene pays nothing for textures, mixes, normal maps or anisotropy. The default (every bit)
// is the conservative one for views built by hand.
enum SceneMaterialBits : uint32_t {
    kSceneResolve = 1u,  // some material needs material_at to resolve it (textures, mixes)
    kSceneFrames = 2u,   // some material has a normal map, a coat normal or anisotropy
    kScenePrograms = 4u, // some material runs node-graph programs (scene/material_program.h)
};

struct NodeInstr;
struct MaterialProgram;

struct SceneView {
    const Vec3* positions = nullptr;
    const Vec3* normals = nullptr;   // per vertex, may be null
    const Vec2* uvs = nullptr;       // per vertex, may be null
    const uint32_t* indices = nullptr;
    const uint32_t* tri_material = nullptr;
    const uint8_t* tri_flags = nullptr;
    const int32_t* tri_light = nullptr;  // light index of an emissive triangle, else -1
    const uint8_t* tri_rays = nullptr;   // RayKinds that see the triangle; null: all see all
    // RayKinds that see light l (a lamp's own ray visibility; emissive triangles and the
    // world: all), and kLampNoShadow where the lamp casts no shadow; null where every lamp is
    // seen by every kind and casts shadows (pt_ray_visibility.h)
    const uint8_t* light_rays = nullptr;
    // light linking (pt: integrator/pt_light_linking.h): a triangle's receiver set (0..63) and
    // per light the sets it lights (bit s); both null where nothing is linked
    const uint8_t* tri_light_set = nullptr;
    const uint64_t* light_receivers = nullptr;
    // shadow linking (pt_light_linking.h): a triangle's blocker set (0..63) and per light the
    // blocker sets that cast its shadows; both null where nothing is shadow-linked
    const uint8_t* tri_shadow_set = nullptr;
    const uint64_t* light_blockers = nullptr;
    // Cycles' Shadow Terminator Geometry Offset of each triangle's mesh (integrator/terminator.h,
    // docs/materials.md "Shadow terminator"); null where no smooth-shaded mesh has one above 0
    const float* tri_terminator = nullptr;
    int32_t num_triangles = 0;
    // 1: some object or lamp is hidden from some ray kind (tri_rays set, or light_rays short of
    // kRayKindsAll for some lamp), decided in HostScene::finish_view: the bidirectional
    // integrators' and lt's ray-kind rules run (bidir_rays_on, lt_rays_on). 0 where light_rays
    // holds only kLampNoShadow (Cast Shadow off). In num_triangles' padding: the kernels'
    // parameter block keeps its layout
    int32_t rays_hidden = 0;

    const Material* materials = nullptr;
    const MaterialTables* material_tables = nullptr;  // one per material: Material::tables
    int32_t num_materials = 0;
    uint32_t material_bits = ~0u;        // SceneMaterialBits

    const Texture* textures = nullptr;
    const uint8_t* texels = nullptr;     // the pool Texture::offset points into
    const float* srgb_lut = nullptr;     // 256 entries: 8-bit sRGB -> linear
    int32_t num_textures = 0;
    const float* tangents = nullptr;     // 4 per vertex (xyz, bitangent sign), may be null
    // compiled node graphs (scene/material_program.h) and the per-vertex attribute channels
    // they read (3 floats each: generated, object, colour attributes, ...)
    const MaterialProgram* programs = nullptr;
    const NodeInstr* program_code = nullptr;
    const float* program_consts = nullptr;
    const float* attributes = nullptr;   // num_attribute_channels x 3 per vertex
    int32_t num_attribute_channels = 0;
    // On the device only (null on the host, which keeps these on its stack): per-thread
    // scratch of a launch, at the thread's index in it (CudaExec::each keeps a launch to
    // device_threads threads; scene/material_program_ops.h launch_thread). Node programs'
    // registers, kProgramRegs floats per thread laid out [register][thread] (ProgramRegs);
    // cis's candidates, kCisCandidates p-hats then as many pick counts, the same layout
    // (integrator/bdpt.h); a resolved mix's leaves, kMixLeaves Materials per thread
    // (bsdf/material.h material_resolve). The CUDA renderer allocates each only when the
    // scene or the integrator uses it.
    uint32_t device_threads = 0;
    float* program_regs = nullptr;
    float* cis_candidates = nullptr;
    Material* mix_leaves = nullptr;

    const Light* lights = nullptr;
    const float* light_cdf = nullptr;    // normalised, by power: lt's light pick
    const float* nee_cdf = nullptr;      // next-event estimation's (no tree); null: no light
    const float* emit_cdf = nullptr;     // normalised, for light sub-paths; null when none can start
    int32_t num_lights = 0;
    int32_t world_light = -1;            // index of the kLightWorld entry or -1
    // next-event estimation's light tree (scene/light_tree.h); light_tree_on 0: light_cdf alone
    const LightTreeNode* light_tree = nullptr;
    int32_t num_tree_nodes = 0;
    const int32_t* distant_lights = nullptr;  // sun and world, picked beside the tree
    int32_t num_distant_lights = 0;
    int32_t light_tree_on = 0;
    // lights a ray can cross (spheres, area lights) and lights seen on a miss (world, sun disk),
    // so that per-ray loops skip the many emissive triangles
    const int32_t* hittable_lights = nullptr;
    int32_t num_hittable_lights = 0;
    const int32_t* miss_lights = nullptr;
    int32_t num_miss_lights = 0;

    int32_t catcher_mode = kCatcherMatte;  // CatcherMode: shadow catchers (pt)
    uint32_t world_rays = kWorldRaysAll;   // WorldRays (pt)
    Vec3 world_color;
    EnvMap env;                          // the world's environment map (width 0: constant)
    CameraView camera;
    float scene_radius = 1.0f;           // half the bounding box's diagonal: offsets, distant
                                         // lights' power, the disk their paths leave
    float emit_radius = 1.0f;            // <= scene_radius, about scene_center: the sphere every
                                         // vertex lies in, the disk the pure light tracer's sun
                                         // and world paths leave (light_path.h, kTightDisk)
    float offset_scale = 1.0f;           // min(1, scene_radius): core/offset.h
    Vec3 scene_center;
    // participating media (scene/medium.h, docs/volumes.md); num_media 0: none, and no stage
    // reads further. A mesh medium holds the world's coefficients too (as Cycles' stack sums).
    const Medium* media = nullptr;
    const int32_t* material_medium = nullptr;  // per material: the medium inside, -1: none
    // per medium x attribute channel (num_attribute_channels): the channel as an affine map of
    // the world position inside a heterogeneous medium (Generated, Object coordinates of its
    // mesh; zero for channels that are not affine); null when no medium is heterogeneous
    const Transform* medium_maps = nullptr;
    int32_t num_media = 0;
    // Volume objects' density grids (scene/medium_grid.h) and their voxels; none: null, 0
    const DensityGrid* grids = nullptr;
    const float* grid_voxels = nullptr;
    int32_t num_grids = 0;
    // the media's majorant bricks (scene/medium_majorant.h) and their values; none: null, 0
    const MajorantGrid* majorant_grids = nullptr;
    const float* majorant_values = nullptr;
    int32_t num_majorant_grids = 0;
    // blackbody colours (scene/medium_fire.h) when a medium has a temperature grid, else null
    const float* blackbody_table = nullptr;
    // 1: some material scatters under its surface (pt's walk stage runs: integrator/pt_sss.h)
    int32_t has_subsurface = 0;
    // 1: some triangle casts no shadow (Cast Shadow off on its object): the bidirectional
    // integrators' next event and connections tell the two queries apart (bidir_no_shadow.h);
    // 2: some of them bound a volume (next event traces both queries through the media)
    int32_t no_shadow_objects = 0;
    // lt's adjoint walk's negative controls for tests (integrator/lt_sss.h; LANTERN_SSS_ADJOINT:
    // 1 "lambert", the exit as the camera side's white Lambert lobe; 2 "nocos", without 1 / |cos|)
    // (3 "nosplit": bdpt_sss_light.h's split left out; 5 "nomedium": the walks' exits leave
    // into vacuum in scenes with media, bdpt_sss.h, lt_sss.h; 4: anything else. Any non-zero
    // value lets the light paths of bdpt, lvc and cis walk Random Walk too, not Skin alone)
    int32_t sss_adjoint_control = 0;
    // lt through a strand (integrator/lt_strand.h): 1 leaves it out, the tests' negative control
    // (LANTERN_LT_STRAND "nothrough")
    int32_t lt_strand_control = 0;
    int32_t world_medium = -1;   // outside every mesh medium, -1: vacuum
    int32_t camera_medium = -1;  // where camera rays start
    // per light (lights): the medium its light paths start in (lt, integrator/lt_medium.h);
    // null without media
    const int32_t* light_medium = nullptr;
    // motion blur (scene/motion.h): moving meshes and the camera's steps; any() false: none
    MotionView motion;
    // strands (scene/curves.h): prims num_triangles .. + curves.num_segs; num_segs 0: none
    CurveView curves;
};

// Texture coordinates of triangle tri at barycentrics (weights of vertices 1 and 2); 0 without uvs.
LANTERN_HD inline Vec2 triangle_uv(const SceneView& s, int32_t tri, Vec2 bary) {
    if (!s.uvs) return Vec2{};
    const uint32_t* idx = s.indices + 3 * tri;
    const float w0 = 1.0f - bary.x - bary.y;
    return Vec2{s.uvs[idx[0]].x * w0 + s.uvs[idx[1]].x * bary.x + s.uvs[idx[2]].x * bary.y,
                s.uvs[idx[0]].y * w0 + s.uvs[idx[1]].y * bary.x + s.uvs[idx[2]].y * bary.y};
}

// Emitted radiance of a material at texture coordinates st (an emission texture, or constant).
LANTERN_HD inline Vec3 material_emission(const SceneView& s, const Material& m, Vec2 st) {
    if (!(m.tex_flags & kTexEmission)) return m.emission;
    const Texture& t = s.textures[m.tex_emission];
    Vec3 c = texture_color(texture_lookup(t, s.texels, s.srgb_lut, st));
    c = Vec3{c.x > 0.0f ? c.x : 0.0f, c.y > 0.0f ? c.y : 0.0f, c.z > 0.0f ? c.z : 0.0f};
    return c * m.emission_scale;
}

}  // namespace lantern
