// The forward pipelines' shadow pass (`visibility::ShadowFilter::record_traced`): Forward+
// and naive, with one ray a pixel, keep their ray's light in the fragment shader instead
// of tracing it there (visibility/shadow_rays.wgsl, `shadow_pass_targets`), and this
// compute pass traces it. On GPUs whose fragment path is slow (the H200) a ray in the
// fragment shader cost 40 times one in compute. The ray starts from the position rebuilt
// from depth, further off its surface by the rebuilt position's error bound, as deferred's
// layouts that store no position start theirs.
//
// It writes the share the filter reads (visibility/shadow_filter.wgsl): 1 or 0 in every
// channel (one ray's share is its visibility), the emission's green in w.

#import manylights::common::view::view
#import manylights::visibility::bvh::light_visible
#import manylights::visibility::rebuilt::{position_from_depth, rebuilt_position_error}
#import manylights::visibility::shadow_pass::NO_SHADOW_RAY

// The shading pass's normals (zero where no surface was drawn) and rays, the depth buffer,
// and the share written.
@group(3) @binding(0) var normals: texture_2d<f32>;
@group(3) @binding(1) var rays: texture_2d<f32>;
@group(3) @binding(2) var depth: texture_depth_2d;
@group(3) @binding(3) var share: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_trace(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = vec2<i32>(id.xy);
    if any(pixel >= vec2<i32>(textureDimensions(share))) {
        return;
    }
    let normal = textureLoad(normals, pixel, 0).xyz;
    let ray = textureLoad(rays, pixel, 0);
    var visible = 1.0;
    // No surface (a zero normal) or no light kept: nothing to trace.
    if dot(normal, normal) > 0.25 && ray.x != NO_SHADOW_RAY {
        let surface_depth = textureLoad(depth, pixel, 0);
        let position = position_from_depth(pixel, surface_depth);
        let error = rebuilt_position_error(surface_depth, position.xyz - view.camera_position.xyz, position.w);
        let point = position.xyz + view.origin.xyz;
        visible = select(0.0, 1.0, light_visible(point, normalize(normal), error, ray.xyz + view.origin.xyz));
    }
    textureStore(share, pixel, vec4<f32>(vec3<f32>(visible), ray.w));
}
