// Positions rebuilt from the depth buffer, and how far off their surface they may lie
// (Rust twin: `visibility::rebuilt_position_error`). Deferred's layouts that store no
// position and the shadow pass of the forward pipelines both rebuild them, and both start
// their shadow rays that much further off the surface.

#import manylights::common::view::view

// The bound's constants (`visibility::REBUILT_DEPTH_ULPS`, `RASTER_PLANE_PIXELS_INVERSE`,
// where their reasons are given).
const REBUILT_DEPTH_ULPS: f32 = f32(#REBUILT_DEPTH_ULPS);
const RASTER_PLANE_PIXELS: f32 = 1.0 / f32(#RASTER_PLANE_PIXELS_INVERSE);

// How far a position rebuilt from `depth` may lie off the surface the rasterizer drew, in
// world units (`visibility::rebuilt_position_error`, its f64 twin, says why): a shadow ray
// starts this much further along the normal (`light_visible`), or a point rebuilt below
// its surface would see the surface itself between it and every light. `from_eye`: the
// rebuilt point minus the eye; `view_depth`: its distance along -Z.
fn rebuilt_position_error(depth: f32, from_eye: vec3<f32>, view_depth: f32) -> f32 {
    let ulp = bitcast<f32>(bitcast<u32>(depth) + 1u) - depth;
    // The projection's depth row and w row (column-major: proj[column][row]):
    // depth = (a z + b) / (c z + e) for view-space z = -view_depth.
    let a = view.proj[2][2];
    let b = view.proj[3][2];
    let c = view.proj[2][3];
    let e = view.proj[3][3];
    let w = -c * view_depth + e;
    // |dz / d depth| = w^2 / |a e - b c|, and one pixel spans 2 w / (proj[1][1] height).
    let view_depth_per_depth = w * w / abs(a * e - b * c);
    let footprint = 2.0 * w / (view.proj[1][1] * view.viewport.y);
    let along_ray = length(from_eye) / max(view_depth, 1e-30);
    return (REBUILT_DEPTH_ULPS * ulp * view_depth_per_depth + RASTER_PLANE_PIXELS * footprint) * along_ray;
}

// The world position of a pixel centre at `depth` (0..1), from the inverse matrices.
fn position_from_depth(pixel: vec2<i32>, depth: f32) -> vec4<f32> {
    let uv = (vec2<f32>(pixel) + 0.5) * view.viewport.zw;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let view_h = view.inverse_proj * ndc;
    let view_position = view_h.xyz / view_h.w;
    let world = view.inverse_view * vec4<f32>(view_position, 1.0);
    // w carries the view depth.
    return vec4<f32>(world.xyz, -view_position.z);
}
