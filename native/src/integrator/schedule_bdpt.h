// The bidirectional integrators' schedule (bdpt, lvc, cis: Algorithms 1 and 2 of the paper), for
// every executor. One iteration = passes within the cache budget; a pass = a light pass over
// L = width x height x spp light paths (trace, sort, shade, store vertices into the cache in
// queue order by an exclusive scan, splat to the camera), the bdpt per-path index (a stable sort
// of cache indices by path), then a camera pass in chunks (trace, sort, the segment's emission,
// shade = the vertex and its next bounce, events = its next event + connections
// (bdpt_camera_events.h), the bounce's shadow rays, compact). The CPU tests a slot's
// shadow rays in one fused item (faster there); the GPU tests them as one batch, a thread per
// ray, then adds the unoccluded ones per slot in a fixed order.
#pragma once

#include <new>
#include <stdexcept>

#include "integrator/bdpt.h"
#include "integrator/bidir_no_shadow.h"
#include "integrator/bidir_no_shadow_medium.h"
#include "integrator/wavefront.h"
#include "integrator/wavefront_motion.h"

namespace lantern {
namespace wf {

template <class Exec>
BdptSettings bdpt_settings(const Wavefront<Exec>& w, const WavefrontStep& st) {
    BdptSettings b = make_bdpt_settings(st.set, st.width, st.height, st.iteration, w.mode, w.mis_r);
    if (w.conn_map_on) b.conn_map = w.conn_map.data();  // (integrator/pixel_conn.h)
    return b;
}

// Samples per light pass so that the cache fits the budget (integrator/wavefront_cache.h).
template <class Exec>
int bdpt_samples_per_pass(Wavefront<Exec>& w, WavefrontStep& st, int spp_it) {
    w.cache_costs = Exec::cache_costs(w.mode == kBdptOwnPath);
    return cache_samples_per_pass(st.cache_budget, w.vertices_per_path, w.cache_costs,
                                  st.set.max_depth, spp_it, st.width, st.height, st.cache_name,
                                  &w.split_warned, *st.warnings);
}

// Scenes with media (bdpt_medium_stages.h): the light pass's camera segments traced through
// the media and volume boundaries they cross, each splat's weight finished with the segment's
// factor at its vertex and multiplied by the transmittance; each at its light path's time
// (motion blur: time_of, BdptTimeOf; bdpt_medium_shadow).
template <class Exec>
int64_t bdpt_camera_segments_medium(Exec& ex, Wavefront<Exec>& w, const SceneView& s, int n,
                                    SessionStats& stats, const BdptTimeOf time_of) {
    const PathState ps = w.ps;
    const BdptState bs = w.bs;
    const int32_t* q = w.queue.data();
    uint8_t* vis = w.visible.data();
    const auto rays = ex.rays();
    int64_t tested = 0;
    ex.timed(stats.time_shadow, [&] {
        tested = ex.count(n, LANTERN_KERNEL(int k) { return ps.shadow_valid[q[k]] != 0; });
        ex.each(n, LANTERN_KERNEL(int k) {
            const int i = q[k];
            uint8_t v = 0;
            if (ps.shadow_valid[i]) {
                Rng track = medium_tracking_rng(ps.rng[i], 1);  // (heterogeneous media)
                const float time =
                    medium_rays_timed(s) ? medium_ray_time(s, time_of(i)) : 0.0f;
                const MediumShadow sh = bdpt_medium_shadow(
                    s, rays, RayKind::kCamera, ps.shadow_o[i], ps.shadow_d[i], ps.shadow_tmax[i],
                    ps.shadow_medium[i], (bs.shadow_kind[i] & kConnNearMedium) != 0, false,
                    &track, time);
                if (!is_black(sh.tr)) {
                    ps.shadow_contrib[i] = bdpt_medium_finish_c(
                        ps.shadow_contrib[i], sh.tr, bs.shadow_wn[i], 0.0f, bs.shadow_kind[i],
                        bs.shadow_mom + i, sh.seg);
                    v = 1;
                }
            }
            vis[i] = v;
        });
    });
    return tested;
}

// Scenes with media: a camera vertex's next-event and connection shadow rays, each through the
// media it crosses, its weight finished (bdpt_medium_stages.h); one item per slot. time: its
// camera path's (motion blur; 0 in still scenes). B: a volume's mesh casts no shadow (its s = 1
// traces both queries out of line, bidir_no_shadow_medium.h): a kernel of its own, so that the
// other scenes' shadow stage does not carry that call's frame (176 B of stack)
template <bool B, class Rays>
LANTERN_HD inline void bdpt_shadow_medium(const SceneView& s, const Rays& rays,
                                          const PathState& ps, const BdptState& bs, int i,
                                          float time) {
    if (ps.shadow_valid[i]) {
        const int32_t kind = bs.shadow_kind[i];
        Rng track = medium_tracking_rng(ps.rng[i], 1);  // (heterogeneous media)
        // shadow linking: a shadow-linked light's blocker sets (bidir_linking.h)
        const int li = s.light_blockers && ps.shadow_light ? ps.shadow_light[i] : -1;
        const MediumShadow sh = bdpt_medium_shadow(
            s, rays, RayKind::kShadow, ps.shadow_o[i], ps.shadow_d[i], ps.shadow_tmax[i],
            ps.shadow_medium[i], (kind & kConnNearMedium) != 0, false, &track, time,
            pt_shadow_linked(s, li) ? s.light_blockers[li] : kAllReceivers,
            true);  // pt's shadow ray: a volume whose mesh casts no shadow skipped (T')
        // an object without shadows (bidir_no_shadow.h): where only it blocks, pt's weight;
        // a volume's mesh among them: both queries (bidir_no_shadow_medium.h)
        if constexpr (B)
            add_radiance(ps, i, bidir_no_shadow_boundary_c(s, rays, RayKind::kIndirect, ps, bs,
                                                           i, sh.tr, time));
        else if (!is_black(sh.tr) && s.no_shadow_objects &&
            bidir_medium_blocked(s, rays, RayKind::kIndirect, ps.shadow_o[i], ps.shadow_d[i],
                                 ps.shadow_tmax[i], time))
            add_radiance(ps, i, bidir_no_shadow_medium_c(ps.shadow_contrib[i], sh.tr,
                                                         bs.shadow_wn[i], bs.shadow_wf[i]));
        else if (!is_black(sh.tr))
            add_radiance(ps, i, bdpt_medium_finish_c(ps.shadow_contrib[i], sh.tr, bs.shadow_wn[i],
                                                     bs.shadow_wf[i], kind, bs.shadow_mom + i,
                                                     sh.seg));
    }
    // connections: the ordinary query where an object casts no shadow (bidir_no_shadow.h)
    const RayKind conn_kind = bidir_conn_kind(s, RayKind::kShadow, RayKind::kIndirect);
    for (int j = 0; j < bs.conn_n[i]; ++j) {
        const size_t e = size_t(i) * bs.conn_cap + j;
        const int32_t kind = bs.conn_kind[e];
        Rng track = bdpt_conn_tracking_rng(ps.rng[i], j);  // (heterogeneous media)
        const MediumShadow sh = bdpt_medium_shadow(
            s, rays, conn_kind, bs.conn_o[e], bs.conn_d[e], bs.conn_tmax[e],
            bs.conn_medium[e], (kind & kConnNearMedium) != 0, (kind & kConnFarMedium) != 0,
            &track, time);
        if (!is_black(sh.tr))
            add_radiance(ps, i, bdpt_medium_finish_c(bs.conn_c[e], sh.tr, bs.conn_wn[e],
                                                     bs.conn_wf[e], kind, bs.conn_mom + e,
                                                     sh.seg));
    }
}

// Whether a chunk runs the stages with linking's tests compiled in (L, bidir_linking.h): where
// the scene has linking's tables; always on the GPU, which builds those chunks only (one set of
// kernels). light_chunk<Exec, Exec::kGpu> is the CPU's chunk without them.
template <class Exec>
bool bidir_chunk_links(const SceneView& s) {
    return Exec::kGpu || bidir_links_on(s);
}

template <class Exec, bool L = true>
void light_chunk(Exec& ex, Wavefront<Exec>& w, const SceneView s, WavefrontStep& st,
                 int64_t first_path, int n) {
    w.media = s.num_media > 0;
    w.resize(n, 0, Exec::kGpu);  // the light pass queues no connections
    SessionStats& stats = *st.stats;
    BdptSettings bst = bdpt_settings(w, st);
    if (w.pilot) {
        bst.iteration = ~uint64_t(0);  // its own random numbers
        w.pilot_count = 0;
    }
    const PathState ps = w.ps;
    const BdptState bs = w.bs;
    const auto sr = stage_rays(ex.rays(), RayKind::kIndirect, RayKind::kShadow);
    int32_t* q0 = w.queue.data();
    ex.timed(stats.time_generate, [&] {
        ex.each(n, LANTERN_KERNEL(int i) {
            bdpt_light_generate(s, ps, bs, bst, i, first_path + i);
            q0[i] = i;
        });
    });
    int active = compact(ex, w, n);
    const bool motion = s.motion.rays_timed();  // moving meshes or strands (docs/motion_blur.md)
    while (active > 0 && !st.cancelled()) {
        stats.rays_light += active;
        if (motion)  // each ray at its path's time (wavefront_motion.h)
            trace_timed(ex, w, active, false, stats,
                        BdptTimeOf{bst, nullptr, 1, first_path, false});
        else
            trace(ex, w, active, false, stats);
        sort_queue(ex, w, s, active, stats);
        const int32_t* q = w.queue.data();
        ex.timed(stats.time_shade, [&] {
            ex.each(active, LANTERN_KERNEL(int k) {
                const int i = q[k];
                bdpt_light_shade<L>(s, ps, bs, bst, i, first_path + i,  // (motion: its time)
                                    motion ? sr.at(bdpt_time(bst, first_path + i)) : sr);
            });
        });
        // store vertices in queue order (places by an exclusive scan of the store flags), then
        // light tracing: camera segments against what the camera sees, then the splats
        auto store_and_splat = [&] {
            const auto t = Clock::now();
            int32_t* f = w.flag.data();
            int32_t* pos = w.scan.data();
            const uint8_t* store = bs.store;
            ex.each(active, LANTERN_KERNEL(int k) { f[k] = store[q[k]]; });
            const int64_t add = ex.exclusive_scan(f, active, pos);
            if (w.pilot) {
                w.pilot_count += add;
                return;
            }
            if (size_t(w.cache_size + add) > w.cache.capacity())  // exact, or CacheOverBudget
                w.cache.grow_keep(cache_grow_capacity(size_t(w.cache_size + add),
                                                      w.cache.capacity(), first_path + n,
                                                      w.pass_light_paths, st.cache_budget,
                                                      w.cache_costs),
                                  size_t(w.cache_size));
            LightVertex* dst = w.cache.data() + w.cache_size;
            const LightVertex* vtx = bs.vertex;
            ex.each(active, LANTERN_KERNEL(int k) {
                if (f[k]) dst[pos[k]] = vtx[q[k]];
            });
            w.cache_size += add;
            ex.sync();
            stats.time_cache += seconds_since(t);
            const BdptTimeOf time_of{bst, nullptr, 1, first_path, false};
            stats.rays_light_tracing +=
                s.num_media > 0 ? bdpt_camera_segments_medium(ex, w, s, active, stats, time_of)
                : motion        ? camera_segments_timed(ex, w, active, stats, time_of)
                                : camera_segments(ex, w, active, stats);
            ex.timed(stats.time_splat, [&] { splat(ex, w, s, st, active); });
        };
        store_and_splat();
        if (s.has_subsurface) {  // the light paths' walks (bdpt_sss_light.h; a kernel of its own
                                 // on a GPU), then their exits' stores and splats
            const auto rays = ex.rays();
            ex.timed(stats.time_shade, [&] {
                ex.each(active, LANTERN_KERNEL(int k) {
                    const int i = q[k];
                    bdpt_light_sss_walk(s, rays, RayKind::kIndirect, ps, bs, bst, i,
                                        first_path + i);
                });
            });
            store_and_splat();
        }
        active = compact(ex, w, active);
    }
    count_dropped(ex, w, n, stats);
}

// bdpt: the vertices of light path j are path_vertex[path_offset[j] .. path_offset[j + 1]), in
// cache order (a stable sort of cache indices by path, then a binary search per path).
template <class Exec>
void index_cache_by_path(Exec& ex, Wavefront<Exec>& w, int64_t light_paths) {
    const int nv = int(w.cache_size);
    const int np = int(light_paths);
    w.path_offset.grow(size_t(np) + 1);
    w.path_key.grow(size_t(std::max(nv, 1)));
    w.path_vertex.grow(size_t(std::max(nv, 1)));
    const LightVertex* cache = w.cache.data();
    uint32_t* key = w.path_key.data();
    int32_t* idx = w.path_vertex.data();
    ex.each(nv, LANTERN_KERNEL(int k) {
        key[k] = uint32_t(cache[k].path);
        idx[k] = k;
    });
    ex.sort_pairs(key, idx, nv, 0, bits_for(uint32_t(np)));
    const uint32_t* sorted = key;
    int32_t* off = w.path_offset.data();
    ex.each(np + 1, LANTERN_KERNEL(int j) {
        int lo = 0, hi = nv;  // first sorted key >= j
        while (lo < hi) {
            const int mid = (lo + hi) >> 1;
            if (int64_t(sorted[mid]) < j) lo = mid + 1; else hi = mid;
        }
        off[j] = lo;
    });
    ex.sync();
}

// Subsurface (bdpt_sss.h): the walks of the camera paths that went under a surface this bounce,
// then their exits' next events, connections and continuations (their shadow rays join the
// bounce's). Two kernels of their own on a GPU, each within the stack cap (docs/cuda_backend.md
// "Subsurface walks of bdpt, lvc, cis and lt").
template <class Exec, class SR>
void bdpt_sss_stages(Exec& ex, Wavefront<Exec>& w, const SceneView& s, const BdptSettings& bst,
                     const LightCache& cache, int active, const int32_t* list, int spp,
                     int64_t first_path, const SR& sr, SessionStats& stats) {
    const PathState ps = w.ps;
    const BdptState bs = w.bs;
    const int32_t* q = w.queue.data();
    const auto rays = ex.rays();
    if (!w.sss_white.data()) {  // the exits' lobe, in the executor's memory (bdpt_sss_exit)
        const Material white = sss_exit_white();
        w.sss_white.grow(1);
        w.sss_white.upload(&white, 1);
    }
    const Material* white = w.sss_white.data();
    ex.timed(stats.time_shade, [&] {
        ex.each(active, LANTERN_KERNEL(int k) {
            const int i = q[k];  // (motion blur: the walk at its camera path's time)
            const float time = s.motion.rays_timed()
                                   ? bdpt_time(bst, camera_path(list, spp, first_path + i))
                                   : 0.0f;
            bdpt_sss_walk(s, rays, RayKind::kIndirect, ps, bs, bst, i, time);
        });
        ex.each(active, LANTERN_KERNEL(int k) {
            const int i = q[k];
            bdpt_sss_exit(s, ps, bs, bst, cache, i, camera_path(list, spp, first_path + i), sr,
                          *white);
        }, 64);
    });
}

template <class Exec, bool L = true>  // (L: bidir_chunk_links)
void camera_chunk(Exec& ex, Wavefront<Exec>& w, const SceneView s, WavefrontStep& st,
                  int64_t first_path, int n) {
    w.media = s.num_media > 0;
    w.no_shadow = s.no_shadow_objects != 0;  // (bidir_no_shadow.h)
    // auto's cis trials with a shadow-linked light: PathState::shadow_mis (bidir_linked_moment)
    w.linked = L && st.set.auto_moments && s.light_blockers && pt_linked_mis(s);
    w.resize(n, w.conn_cap, Exec::kGpu);
    SessionStats& stats = *st.stats;
    const BdptSettings bst = bdpt_settings(w, st);
    const PathState ps = w.ps;
    const BdptState bs = w.bs;
    const bool own = w.mode == kBdptOwnPath;
    const LightCache cache{w.cache.data(), int32_t(w.cache_size),
                           own ? w.path_offset.data() : nullptr,
                           own ? w.path_vertex.data() : nullptr};
    const auto rays = ex.rays();
    const auto sr = stage_rays(rays, RayKind::kIndirect, RayKind::kShadow, !st.set.soft_visibility);
    int32_t* q0 = w.queue.data();
    const int32_t* list = st.pixel_list;  // adaptive sampling's pixels, or null: all
    const int spp = st.set.spp_per_iteration;
    ex.timed(stats.time_generate, [&] {
        ex.each(n, LANTERN_KERNEL(int i) {
            bdpt_camera_generate(s, ps, bs, bst, i, camera_path(list, spp, first_path + i));
            q0[i] = i;
        });
    });
    int active = n;
    stats.rays_camera += n;
    bool first = true;
    // moving meshes: every ray of the pass at its path's time (wavefront_motion.h)
    const bool motion = s.motion.rays_timed();
    const BdptTimeOf time_of{bst, list, spp, first_path, true};
    while (active > 0 && !st.cancelled()) {
        if (motion)
            trace_timed(ex, w, active, first, stats, time_of);
        else
            trace(ex, w, active, first, stats);
        sort_queue(ex, w, s, active, stats);
        const int32_t* q = w.queue.data();
        // the segment's emission (without media), the shade, the queued vertices' next events
        // and connections: three stages, each a kernel with its own stack on a GPU
        // (bdpt_camera_events.h)
        ex.timed(stats.time_shade, [&] {
            if (s.num_media == 0) {
                ex.each(active, LANTERN_KERNEL(int k) {
                    const int i = q[k];
                    const int64_t path = camera_path(list, spp, first_path + i);
                    bdpt_camera_emission_stage<L>(  // (motion: at its time; else sr's, 0)
                        s, ps, bs, bst, i, path,
                        stage_rays_at(sr, motion ? bdpt_time(bst, path) : sr.time));
                }, 64);
            }
            ex.each(active, LANTERN_KERNEL(int k) {
                const int i = q[k];
                const int64_t path = camera_path(list, spp, first_path + i);
                bdpt_camera_shade<L>(s, ps, bs, bst, cache, i, path,  // (motion: its time)
                                     stage_rays_at(sr, motion ? bdpt_time(bst, path) : sr.time));
            }, 64);
            ex.each(active, LANTERN_KERNEL(int k) {
                const int i = q[k];
                const int64_t path = camera_path(list, spp, first_path + i);
                bdpt_camera_events<L>(s, ps, bs, bst, cache, i, path,  // (motion: its time)
                                      stage_rays_at(sr, motion ? bdpt_time(bst, path) : sr.time));
            }, 64);
        });
        if (s.has_subsurface)  // the walks of this bounce's subsurface paths (bdpt_sss.h)
            bdpt_sss_stages(ex, w, s, bst, cache, active, list, spp, first_path, sr, stats);
        // every shadow ray of the bounce: next event and connections (objects without
        // shadows: bidir_no_shadow.h)
        const RayKind conn_kind = bidir_conn_kind(s, RayKind::kShadow, RayKind::kIndirect);
        ex.timed(stats.time_shadow, [&] {
            stats.rays_shadow +=
                ex.count(active, LANTERN_KERNEL(int k) { return ps.shadow_valid[q[k]] != 0; });
            stats.rays_connection +=
                ex.sum_of(active, LANTERN_KERNEL(int k) { return bs.conn_n[q[k]]; });
            if (w.mode == kCisResampled) {  // M of each camera vertex's pixel (pixel_conn.h)
                stats.cis_candidates += bst.conn_map ? ex.sum_of(active, LANTERN_KERNEL(int k) {
                    return camera_settings(bst, pixel_conn_of_slot(bst, bs, q[k])).candidates;
                }) : int64_t(active) * bst.candidates;
            }
            if (s.num_media > 0 && s.no_shadow_objects == 2) {  // (a volume's mesh unshadowed)
                ex.each(active, LANTERN_KERNEL(int k) {
                    const int i = q[k];
                    bdpt_shadow_medium<true>(s, rays, ps, bs, i, medium_rays_timed(s) ?
                                             medium_ray_time(s, time_of(i)) : 0.0f);
                }, 64);
            } else if (s.num_media > 0) {  // through media, weights finished (bdpt_medium_stages.h)
                ex.each(active, LANTERN_KERNEL(int k) {
                    const int i = q[k];  // (motion: at its camera path's time)
                    bdpt_shadow_medium<false>(s, rays, ps, bs, i, medium_rays_timed(s) ?
                                              medium_ray_time(s, time_of(i)) : 0.0f);
                }, 64);
            } else if constexpr (!Exec::kGpu) {  // one item per slot, in a fixed order
                ex.each(active, LANTERN_KERNEL(int k) {
                    const int i = q[k];
                    const float time = motion ? time_of(i) : 0.0f;  // (Ray's default)
                    if (ps.shadow_valid[i]) {
                        Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
                        r.time = time;
                        if (L ? !bidir_nee_occluded(s, rays, RayKind::kShadow, ps, i, r)
                              : !rays.occluded(r, RayKind::kShadow))
                            add_radiance(ps, i, bidir_nee_value(ps, bs, i, bidir_nee_visible(
                                                    s, rays, RayKind::kIndirect, r)));
                    }
                    for (int j = 0; j < bs.conn_n[i]; ++j) {
                        const size_t e = size_t(i) * bs.conn_cap + j;
                        Ray r{bs.conn_o[e], bs.conn_d[e], 0.0f, bs.conn_tmax[e]};
                        r.time = time;
                        if (!rays.occluded(r, conn_kind)) add_radiance(ps, i, bs.conn_c[e]);
                    }
                }, 64);
            } else {  // one thread per ray, [next event, connections...] per slot
                const int per = bs.conn_cap + 1;
                uint8_t* vis = w.conn_vis.data();
                ex.each(active * per, LANTERN_KERNEL(int e) {
                    const int k = e / per, j = e - k * per;
                    const int i = q[k];
                    uint8_t v = 0;
                    const float time = motion ? time_of(i) : 0.0f;  // (Ray's default)
                    if (j == 0) {
                        if (ps.shadow_valid[i]) {
                            Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
                            r.time = time;
                            v = bidir_nee_occluded(s, rays, RayKind::kShadow, ps, i, r)
                                    ? 0
                                    : bidir_nee_visible(s, rays, RayKind::kIndirect, r);
                        }
                    } else if (j - 1 < bs.conn_n[i]) {
                        const size_t c = size_t(i) * bs.conn_cap + (j - 1);
                        Ray r{bs.conn_o[c], bs.conn_d[c], 0.0f, bs.conn_tmax[c]};
                        r.time = time;
                        v = rays.occluded(r, conn_kind) ? 0 : 1;
                    }
                    vis[e] = v;
                });
                ex.each(active, LANTERN_KERNEL(int k) {
                    const int i = q[k];
                    const uint8_t* v = vis + size_t(k) * per;
                    if (v[0]) add_radiance(ps, i, bidir_nee_value(ps, bs, i, v[0]));
                    for (int j = 0; j < bs.conn_n[i]; ++j)
                        if (v[1 + j]) add_radiance(ps, i, bs.conn_c[size_t(i) * bs.conn_cap + j]);
                });
            }
        });
        active = compact(ex, w, active);
        if (active) stats.rays_indirect += active;
        first = false;
    }
    if (st.cancelled()) return;
    film(ex, w, st, first_path, n);
}

// The pilot: a small light pass with its own random numbers, stored nowhere, counts the cache
// vertices per light path before the first iteration (its passes and, for lvc / cis, r).
template <class Exec>
void measure_cache_rate(Exec& ex, Wavefront<Exec>& w, const SceneView& s, WavefrontStep& st) {
    const int64_t light_paths = int64_t(st.width) * st.height * st.set.spp_per_iteration;
    const int pilot = int(std::min<int64_t>(light_paths, 1 << 14));
    if (bdpt_light_paths(st.set, st.width, st.height) == 0) {  // no light pass, no cache
        w.vertices_per_path = 0.0;
        return;
    }
    w.pilot = true;
    if (bidir_chunk_links<Exec>(s))
        light_chunk<Exec, true>(ex, w, s, st, 0, pilot);
    else
        light_chunk<Exec, Exec::kGpu>(ex, w, s, st, 0, pilot);
    w.pilot = false;
    if (!st.cancelled()) w.vertices_per_path = double(w.pilot_count) / pilot;
}

// One pass: light pass into the cache, its index (bdpt), camera pass.
template <class Exec>
bool bdpt_pass(Exec& ex, Wavefront<Exec>& w, const SceneView& s, WavefrontStep& st) {
    const int spp_it = st.set.spp_per_iteration;
    const int64_t light_paths = bdpt_light_paths(st.set, st.width, st.height);
    SessionStats& stats = *st.stats;
    // MIS count of a connection, r = N L / |C|: bdpt connects to every vertex of one light path
    // (r = 1); lvc and cis take N picks out of |C| vertices from L paths, r from the previous
    // iteration's cache (or the pilot), so the weights never depend on the paths they weight;
    // without light paths (SessionSettings::light_path_fraction 0) there are no connections
    auto t = Clock::now();
    if (light_paths == 0)
        w.mis_r = 0.0f;
    else if (w.mode == kBdptOwnPath || !(w.vertices_per_path > 0.0))
        w.mis_r = 1.0f;
    else
        w.mis_r = float(st.set.connections / w.vertices_per_path);
    // a connection map (pixel_conn.h) of lvc / cis: in the executor's memory, for this pass
    const std::vector<uint8_t>& map = st.set.connection_map;
    w.conn_map_on = !map.empty() && w.mode != kBdptOwnPath && w.mis_r > 0.0f;
    int n_max = st.set.connections;
    if (w.conn_map_on) {
        w.conn_map.grow(map.size());
        w.conn_map.upload(map.data(), map.size());
        n_max = 1;
        for (size_t k = 0; k < map.size(); k += 2) n_max = std::max(n_max, int(map[k]));
    }
    // the cache starts at the capacity the measured rate predicts (wavefront_cache.h)
    w.pass_light_paths = light_paths;
    w.release_index();  // the last pass's
    w.cache_size = 0;
    const size_t want =
        cache_initial_capacity(w.vertices_per_path, light_paths, st.cache_budget, w.cache_costs);
    if (w.cache.capacity() < want ||
        w.cache.capacity() > cache_max_vertices(st.cache_budget, w.cache_costs, double(light_paths)))
        w.cache.release();  // empty: released before the new one, never both at once
    w.cache.grow(want);
    for (int64_t p0 = 0; p0 < light_paths; p0 += st.chunk_paths) {
        const int n = int(std::min<int64_t>(st.chunk_paths, light_paths - p0));
        if (bidir_chunk_links<Exec>(s))
            light_chunk<Exec, true>(ex, w, s, st, p0, n);
        else
            light_chunk<Exec, Exec::kGpu>(ex, w, s, st, p0, n);
        if (st.cancelled()) return false;
    }
    stats.cache_vertices = w.cache_size;
    if (light_paths > 0) w.vertices_per_path = double(w.cache_size) / double(light_paths);
    stats.time_light_pass += seconds_since(t);
    t = Clock::now();
    if (w.mode == kBdptOwnPath) index_cache_by_path(ex, w, light_paths);
    stats.cache_memory_peak = w.cache_meter.peak;
    stats.time_cache += seconds_since(t);
    t = Clock::now();
    w.conn_cap = w.mode == kBdptOwnPath ? std::max(1, st.set.max_depth - 1) : n_max;
    const int64_t pixels = st.camera_pixels();
    const int chunk = std::max(spp_it, std::min(st.chunk_paths, st.shadow_budget / w.conn_cap));
    const int64_t chunk_pixels = std::max<int64_t>(1, chunk / spp_it);
    for (int64_t q0 = 0; q0 < pixels; q0 += chunk_pixels) {
        const int64_t np = std::min(chunk_pixels, pixels - q0);
        if (bidir_chunk_links<Exec>(s))
            camera_chunk<Exec, true>(ex, w, s, st, q0 * spp_it, int(np * spp_it));
        else
            camera_chunk<Exec, Exec::kGpu>(ex, w, s, st, q0 * spp_it, int(np * spp_it));
        if (st.cancelled()) return false;
    }
    stats.time_camera_pass += seconds_since(t);
    return true;
}

// An iteration as passes within the cache budget: past it, several light + camera passes of
// fewer samples each (the same estimator: more, smaller iterations). A pass whose cache would
// pass the budget after all stops, and the iteration starts again from its first pass with the
// rate measured so far and passes of at most half the samples; the counts do not depend on
// scheduling, so neither do the bits.
template <class Exec>
bool bidirectional_iteration(Exec& ex, Wavefront<Exec>& w, const SceneView& s,
                             WavefrontStep& st) {
    if (!(w.vertices_per_path >= 0.0)) {
        measure_cache_rate(ex, w, s, st);
        if (st.cancelled()) return false;
    }
    const int spp_it = st.set.spp_per_iteration;
    const uint64_t iteration0 = st.iteration;
    const SessionStats stats0 = *st.stats;
    int per_pass = bdpt_samples_per_pass(w, st, spp_it);
    for (;;) {
        std::string over;
        double rate = 0.0;
        for (int done = 0; done < spp_it;) {
            const int n = std::min(per_pass, spp_it - done);
            st.set.spp_per_iteration = n;
            bool ok = false;
            try {
                ok = bdpt_pass(ex, w, s, st);
            } catch (const CacheOverBudget& e) {
                over = e.what();
                rate = e.vertices_per_path;
            } catch (const std::bad_alloc&) {
                st.set.spp_per_iteration = spp_it;
                w.release_cache();
                throw std::runtime_error(
                    "out of memory for the light vertex cache (" + std::to_string(st.width) +
                    "x" + std::to_string(st.height) + ", " + std::to_string(n) +
                    " samples per pass); lower the resolution or use integrator 'pt'");
            }
            st.set.spp_per_iteration = spp_it;
            if (!over.empty()) break;
            if (!ok) return false;
            ++st.iteration;  // every pass draws its own random numbers
            done += n;
        }
        if (over.empty()) return true;
        w.release_cache();
        if (per_pass == 1)
            throw std::runtime_error(over + ", at one sample per pass: raise cache_budget_mb, "
                                            "or lower the resolution or max_depth, or use "
                                            "integrator 'pt'");
        st.iteration = iteration0;
        *st.stats = stats0;
        st.stats->cache_memory_peak = w.cache_meter.peak;
        double* sum = st.sum;
        ex.each(st.width * st.height * 3, LANTERN_KERNEL(int k) { sum[k] = 0.0; });
        w.vertices_per_path = std::max(w.vertices_per_path, rate);
        per_pass = std::max(1, std::min(per_pass / 2, bdpt_samples_per_pass(w, st, spp_it)));
        if (!w.restart_warned) {
            w.restart_warned = true;
            st.warnings->push_back(std::string(st.cache_name) + ": " + over +
                                   "; the iteration ran again in passes of " +
                                   std::to_string(per_pass) + " samples");
        }
    }
}

}  // namespace wf
}  // namespace lantern
