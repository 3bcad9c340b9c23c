// The clustered radiance of a surface in one call, for an engine's own fragment or compute
// shader: every light of the point's cluster list (points, spots, spheres, rectangles,
// triangles, each by its shape, as manylights' pipelines shade it) and, with the far
// field (CLUSTERED_RADIANCE_FAR_FIELD), the cluster's cut of the light tree, through
// manylights' BRDF (glTF's metallic-roughness, lights/brdf.wgsl):
//
//     let radiance = clustered_radiance(frag_coord.xy, view_depth, world, normal, view_dir,
//                                       base_color, metallic, roughness);
//
// Positions are world space (LIGHTS_IN_WORLD_SPACE: no camera of ours is read), and the
// only bindings are the lists' (listed_lights.wgsl, far_terms.wgsl) and the BRDF's table
// (lights/specular_albedo.wgsl), at the groups the engine chose
// (`cluster::ListedLights::clustered_radiance_wgsl`). No shadows: the BVH's query
// (visibility/bvh.wgsl) is the engine's to call, per light, in its own loop.

#import manylights::cluster::listed_lights::{lights_at, listed_light, lights, NOT_LISTED}
#import manylights::lights::shading::{loop_light, shade_loop_light, FALLOFF_WINDOWED_INVERSE_SQUARE}
#import manylights::lights::brdf::loop_sum_radiance
#import manylights::lights::pbr_for_engines::pbr_surface
#ifdef CLUSTERED_RADIANCE_FAR_FIELD
#import manylights::cluster::far_terms::{far_cut, far_entry, far_light}
#import manylights::cluster::far_shading::{shade_aggregate, shade_light_complement}
#endif

// The radiance towards the eye at `position` (world space), seen at pixel position `pixel`
// (pixel centres at .5, as @builtin(position).xy) and view depth `view_depth` (the
// positive distance along the camera's view direction), with unit `normal`, `view_dir`
// the unit direction from the point to the eye, and glTF's base colour (linear), metallic
// and perceptual roughness.
fn clustered_radiance(pixel: vec2<f32>, view_depth: f32, position: vec3<f32>, normal: vec3<f32>, view_dir: vec3<f32>, base_color: vec3<f32>, metallic: f32, roughness: f32) -> vec3<f32> {
    let surface = pbr_surface(position, normal, view_dir, base_color, metallic, roughness);
    let list = lights_at(pixel, view_depth);
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < list.candidates; i++) {
        let index = listed_light(list, i);
        if index == NOT_LISTED {
            continue;
        }
        radiance += shade_loop_light(surface, view_dir, loop_light(lights[index]), FALLOFF_WINDOWED_INVERSE_SQUARE);
    }
#ifdef CLUSTERED_RADIANCE_FAR_FIELD
    // Beyond the lights' radii: the cut's aggregates, and each light of a node marked
    // exact through the complement of its window (windowed plus complement is the plain
    // inverse square).
    let cut = far_cut(list.cluster);
    for (var k = 0u; k < cut.entries; k++) {
        let entry = far_entry(cut, k);
        if entry.aggregate {
            radiance += shade_aggregate(surface, view_dir, entry.node);
            continue;
        }
        for (var i = entry.node.first; i < entry.node.first + entry.node.count; i++) {
            radiance += shade_light_complement(surface, view_dir, loop_light(lights[far_light(i)]));
        }
    }
#endif
    return loop_sum_radiance(surface, radiance);
}
