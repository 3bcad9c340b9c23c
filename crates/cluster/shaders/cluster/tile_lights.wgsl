// The clustered light loop for a compute pass over 8x8-pixel tiles (deferred's `tiles`
// lighting path). The pixels of a tile that share a cluster load its list into workgroup
// memory once, 64 lights at a time (one a thread), keep the lights whose reach meets the
// box around those pixels' surfaces, and every one of them evaluates the kept lights from
// there: a light is read from memory once per tile instead of once per pixel, and a pixel
// skips the lights that reach its cluster's box but not its tile's surfaces.
//
// The radiance equals the per-pixel loop's (`shade_cluster` in cluster_lights.wgsl) term
// for term and in the same order: a light is dropped only when it reaches no pixel it was
// dropped for (its term there is exactly zero), and the kept ones stay in list order.
// Every thread of the workgroup calls `shade_tile_lights` from uniform control flow (it
// has barriers), with or without a surface of its own.

#import manylights::common::surface::Surface
#import manylights::lights::shading::{LoopLight, loop_light}
#import manylights::lights::brdf::{loop_sum_radiance, surface_for_loop}
#import manylights::cluster::bounds::{ordered_code, from_ordered_code}
#import manylights::cluster::listed_lights::{lights, NOT_LISTED, cluster_list, listed_light}
#import manylights::cluster::cluster_lights::{
    shade_listed_light, listed_light_range, light_reaches_box, begin_pixel_shadows,
    with_pixel_shadows
}
#ifdef LIGHT_LOOP_FAR_TREE
#import manylights::cluster::cluster_lights::shade_far_tree
#endif

// Threads of a tile (the screen tile's, 8x8), and so the lights loaded at a time: a bit
// each in the kept-candidate masks below (the cluster crate asserts there are 64).
const TILE_THREADS: u32 = #SCREEN_TILE * #SCREEN_TILE;
const NO_CLUSTER: u32 = 0xffffffffu;

// The smallest cluster of the tile's pixels not yet shaded (the one shaded next).
var<workgroup> next_cluster: atomic<u32>;
var<workgroup> current_cluster: u32;
// The box of that cluster's surfaces in the tile, camera-relative (order-preserving codes).
var<workgroup> box_low: array<atomic<u32>, 3>;
var<workgroup> box_high: array<atomic<u32>, 3>;
// Which of a chunk's 64 candidates are kept, a bit each. Two sets, used by alternate
// chunks, so that one is cleared while the other is read.
var<workgroup> kept_bits: array<array<atomic<u32>, 2>, 2>;
// The kept lights of the chunk, in list order, with their stochastic ranges: as the loop
// evaluates them (`LoopLight`), so what depends on the light alone is worked out once per
// tile.
var<workgroup> kept_lights: array<LoopLight, TILE_THREADS>;
var<workgroup> kept_ranges: array<f32, TILE_THREADS>;

// Radiance towards the eye at `surface` from the lights of `cluster` (and its far-field
// cut), as `shade_cluster` sums them. `thread`: the local invocation index; `has_surface`: the
// thread has a surface to shade (threads outside the screen or on background help load,
// and return zero).
fn shade_tile_lights(thread: u32, has_surface: bool, surface: Surface, view_dir: vec3<f32>, cluster: u32) -> vec3<f32> {
    var radiance = vec3<f32>(0.0);
    let lit = surface_for_loop(surface, view_dir);
    begin_pixel_shadows(surface);
    var pending = has_surface;
    var parity = 0u;
    // One round per distinct cluster among the tile's pixels, smallest first.
    loop {
        if thread == 0u {
            atomicStore(&next_cluster, NO_CLUSTER);
            // A workgroup may call this more than once (the blended layers shade one
            // depth rank a call): the set a call starts with may hold the bits of the
            // previous call's last chunk. Every read of them was before that call's
            // last barrier.
            if parity == 0u {
                atomicStore(&kept_bits[0][0], 0u);
                atomicStore(&kept_bits[0][1], 0u);
            }
            for (var axis = 0u; axis < 3u; axis++) {
                atomicStore(&box_low[axis], 0xffffffffu);
                atomicStore(&box_high[axis], 0u);
            }
        }
        workgroupBarrier();
        if pending {
            atomicMin(&next_cluster, cluster);
        }
        workgroupBarrier();
        if thread == 0u {
            current_cluster = atomicLoad(&next_cluster);
        }
        let current = workgroupUniformLoad(&current_cluster);
        if current == NO_CLUSTER {
            break;
        }
        let mine = pending && cluster == current;
        if mine {
            for (var axis = 0u; axis < 3u; axis++) {
                atomicMin(&box_low[axis], ordered_code(surface.position[axis]));
                atomicMax(&box_high[axis], ordered_code(surface.position[axis]));
            }
        }
        workgroupBarrier();
        var low: vec3<f32>;
        var high: vec3<f32>;
        for (var axis = 0u; axis < 3u; axis++) {
            low[axis] = from_ordered_code(atomicLoad(&box_low[axis]));
            high[axis] = from_ordered_code(atomicLoad(&box_high[axis]));
        }

        // The cluster's candidates, as shade_cluster walks them (its list, or when the
        // list was cut short every light, `listed_light` keeping those whose sphere meets
        // the cluster's box).
        let list = cluster_list(current);
        let candidates = list.candidates;
        for (var chunk = 0u; chunk < candidates; chunk += TILE_THREADS) {
            var keep = false;
            var light: LoopLight;
            var range = 0.0;
            let candidate = chunk + thread;
            if candidate < candidates {
                let index = listed_light(list, candidate);
                keep = index != NOT_LISTED;
                if keep {
                    light = loop_light(lights[index]);
                    range = listed_light_range(index);
                    keep = light_reaches_box(light, range, low, high);
                }
                if keep {
                    atomicOr(&kept_bits[parity][thread / 32u], 1u << (thread % 32u));
                }
            }
            workgroupBarrier();
            let bits = vec2<u32>(atomicLoad(&kept_bits[parity][0]), atomicLoad(&kept_bits[parity][1]));
            if keep {
                // Its place among the kept: how many threads before it kept theirs.
                let word = thread / 32u;
                let before = (1u << (thread % 32u)) - 1u;
                let slot = select(0u, countOneBits(bits.x), word == 1u) + countOneBits(bits[word] & before);
                kept_lights[slot] = light;
                kept_ranges[slot] = range;
            }
            // The other set was last read before the previous chunk's final barrier.
            if thread == 0u {
                atomicStore(&kept_bits[parity ^ 1u][0], 0u);
                atomicStore(&kept_bits[parity ^ 1u][1], 0u);
            }
            parity ^= 1u;
            let kept = countOneBits(bits.x) + countOneBits(bits.y);
            workgroupBarrier();
            if mine {
                // Two lights an iteration, summed in list order: their terms are independent
                // until the sum, so the compiler interleaves them (H200, 100,000 lights:
                // 8.14 -> 7.64 ms; four an iteration measured 7.67, and the terms without
                // branches, their early returns made selects, 8.02).
                var k = 0u;
                for (; k + 1u < kept; k += 2u) {
                    let first = shade_listed_light(lit, view_dir, kept_lights[k], kept_ranges[k]);
                    let second = shade_listed_light(lit, view_dir, kept_lights[k + 1u], kept_ranges[k + 1u]);
                    radiance += first;
                    radiance += second;
                }
                if k < kept {
                    radiance += shade_listed_light(lit, view_dir, kept_lights[k], kept_ranges[k]);
                }
            }
            workgroupBarrier();
        }
        if mine {
            pending = false;
        }
        // Everyone has read the box before the next round resets it.
        workgroupBarrier();
    }
#ifdef LIGHT_LOOP_FAR_TREE
    // The far field's cut, per pixel: sharing it as the lists are shared measured slower
    // (H200, 1,000,000 lights: 1.96 against 1.29 ms at 64 slots), because a tile whose
    // pixels fall in several clusters then walks their cuts one after another, where
    // per-pixel loops walk them side by side.
    if has_surface {
        radiance += shade_far_tree(lit, view_dir, cluster).radiance;
    }
#endif
    if !has_surface {
        return vec3<f32>(0.0);
    }
    return with_pixel_shadows(surface, loop_sum_radiance(lit, radiance));
}
