// The spatial filter of the shadow rays' visible share (`visibility::Shadows::RaysSpatial`),
// after deferred's compute lighting: two fullscreen passes, along rows (`fs_rows`, into a
// share texture of its own) then along columns (`fs_columns`, adding the unshadowed
// radiance times the filtered share to the HDR target, which holds the emission).
//
// Only the share is filtered, never the radiance: each pixel keeps its own exact
// unshadowed sum (its texture and highlights), and takes its neighbours' shares weighted by
// their unshadowed radiance per channel (the ratio of filtered visible over filtered
// unshadowed light, as Heitz, Hill and McGuire 2018 filter their ratio estimator), so a
// neighbour that gets no light counts for nothing.
//
// Edge-aware by walking: from the pixel outwards, one direction at a time, each tap must
// lie on the pixel's own plane (its depth-rebuilt position within `PLANE_TOLERANCE` of the
// depth of the plane through the pixel's position with the pixel's normal) and face the
// same way (normals within `NORMAL_COS`); the first tap that does not ends the walk. A
// wall between a lit and a dark room stops it even where both floors lie in one plane,
// and a frame with nothing in shadow (every share 1) comes out exactly as it went in.

#import manylights::common::view::view
#import manylights::common::fullscreen::{FullscreenOutput, fullscreen_vertex}
#import manylights::deferred::codecs::position_from_depth

// The lighting pass's unshadowed radiance (w unused), the share to filter (the rays'
// for rows, the rows' for columns), the normal (w: 1 where a surface covers the pixel),
// and the depth buffer the positions are rebuilt from.
@group(1) @binding(0) var unshadowed: texture_2d<f32>;
@group(1) @binding(1) var share: texture_2d<f32>;
@group(1) @binding(2) var normals: texture_2d<f32>;
@group(1) @binding(3) var depth: texture_depth_2d;

// Taps each side of the pixel, and the Gaussian's standard deviation in pixels.
const RADIUS: i32 = 6;
const SIGMA: f32 = 3.0;
// A tap may lie off the pixel's plane by this share of the camera's distance from that
// plane: the half-float normal's error (2^-11 of each component) over the few pixels
// between them, the rebuilt positions' error (a few f32 ulps of depth), and gentle
// curvature (Sponza's columns), with room; a ledge or a wall's edge is far beyond it.
const PLANE_TOLERANCE: f32 = 0.01;
// Normals within 25 degrees.
const NORMAL_COS: f32 = 0.9;

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> FullscreenOutput {
    return fullscreen_vertex(index);
}

// The position of the surface at `pixel` relative to the camera (rebuilt from depth as
// the lighting rebuilt it).
fn rebuilt(pixel: vec2<i32>) -> vec3<f32> {
    return position_from_depth(pixel, textureLoad(depth, pixel, 0)).xyz - view.camera_position.xyz;
}

// The share at `pixel`, filtered along `axis` (one pixel step).
fn filtered_share(pixel: vec2<i32>, axis: vec2<i32>) -> vec3<f32> {
    let own = textureLoad(share, pixel, 0).rgb;
    let normal = textureLoad(normals, pixel, 0);
    if normal.w == 0.0 {
        return own;
    }
    let centre = rebuilt(pixel);
    let plane = dot(normal.xyz, centre);
    let own_light = textureLoad(unshadowed, pixel, 0).rgb;
    var visible = own * own_light;
    var all = own_light;
    let size = vec2<i32>(textureDimensions(share));
    for (var side = -1; side <= 1; side += 2) {
        for (var k = 1; k <= RADIUS; k++) {
            let tap = pixel + axis * (k * side);
            if any(tap < vec2<i32>(0)) || any(tap >= size) {
                break;
            }
            let tap_normal = textureLoad(normals, tap, 0);
            if tap_normal.w == 0.0 || dot(tap_normal.xyz, normal.xyz) < NORMAL_COS {
                break;
            }
            // The tap's position, and where its view ray meets the pixel's plane: the same
            // view depth scaled by how far along the ray the plane lies.
            let position = rebuilt(tap);
            let along = dot(normal.xyz, position);
            if abs(along - plane) > PLANE_TOLERANCE * abs(plane) {
                break;
            }
            let weight = exp(-f32(k * k) / (2.0 * SIGMA * SIGMA));
            let light = weight * textureLoad(unshadowed, tap, 0).rgb;
            visible += light * textureLoad(share, tap, 0).rgb;
            all += light;
        }
    }
    return select(own, visible / all, all > vec3<f32>(0.0));
}

@fragment
fn fs_rows(in: FullscreenOutput) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.position.xy);
    return vec4<f32>(filtered_share(pixel, vec2<i32>(1, 0)), 0.0);
}

// Added to the HDR target (its emission): the unshadowed radiance times the share.
@fragment
fn fs_columns(in: FullscreenOutput) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.position.xy);
    let light = textureLoad(unshadowed, pixel, 0).rgb;
    return vec4<f32>(light * filtered_share(pixel, vec2<i32>(0, 1)), 0.0);
}
