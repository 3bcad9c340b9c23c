// The spatial filter of the shadow rays' visible share (`visibility::Shadows::RaysSpatial`),
// after deferred's compute lighting: two compute passes over 8x8 tiles, along rows
// (`cs_rows`, into a share texture of its own) then along columns (`cs_columns`, writing
// the HDR target: the emission plus the unshadowed radiance times the filtered share).
// Compute, not fullscreen fragment passes: on the H200, whose fragment path is slow, the
// two fragment passes took 2.97 ms each at 1920x1080.
//
// Only the share is filtered, never the radiance: each pixel keeps its own exact
// unshadowed sum (its texture and highlights), and takes its neighbours' shares weighted by
// their unshadowed radiance per channel (the ratio of filtered visible over filtered
// unshadowed light, as Heitz, Hill and McGuire 2018 filter their ratio estimator), so a
// neighbour that gets no light counts for nothing.
//
// Edge-aware by walking: from the pixel outwards, one direction at a time, each tap must
// lie on the pixel's plane (its depth-rebuilt position within `PLANE_TOLERANCE` of the plane
// through the pixel's position with the pixel's normal) and face the same way (normals
// within `NORMAL_COS`); the first tap that does not ends the walk. A wall between a lit
// and a dark room stops it even where both floors lie in one plane, and a frame with
// nothing in shadow (every share 1) comes out exactly as it went in.
//
// The lighting pass's emission rides in the inputs' fourth channels (r, g, b in the
// unshadowed radiance's, the share's and the normal's): its output group has room for
// four storage textures, WebGPU's guarantee, and the HDR target is the fourth.

#import manylights::common::view::view
#import manylights::deferred::codecs::position_from_depth

// The lighting pass's unshadowed radiance, the share to filter (the rays' for rows, the
// rows' for columns), the normal (zero where no surface covers the pixel), each with a
// channel of the emission in w, and the depth buffer the positions are rebuilt from.
@group(1) @binding(0) var unshadowed: texture_2d<f32>;
@group(1) @binding(1) var share: texture_2d<f32>;
@group(1) @binding(2) var normals: texture_2d<f32>;
@group(1) @binding(3) var depth: texture_depth_2d;
// The rows pass's output (the filtered share, the emission's green in w), or the HDR
// target for the columns pass.
@group(1) @binding(4) var output: texture_storage_2d<rgba16float, write>;

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

// Whether a surface covers a pixel: its normal is a unit vector, zero where none.
fn covered(normal: vec4<f32>) -> bool {
    return dot(normal.xyz, normal.xyz) > 0.25;
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
    if !covered(normal) {
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
            if !covered(tap_normal) || dot(tap_normal.xyz, normal.xyz) < NORMAL_COS {
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

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = vec2<i32>(id.xy);
    if any(pixel >= vec2<i32>(textureDimensions(share))) {
        return;
    }
    let green = textureLoad(share, pixel, 0).w;
    textureStore(output, pixel, vec4<f32>(filtered_share(pixel, vec2<i32>(1, 0)), green));
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_columns(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = vec2<i32>(id.xy);
    if any(pixel >= vec2<i32>(textureDimensions(share))) {
        return;
    }
    let light = textureLoad(unshadowed, pixel, 0);
    let normal = textureLoad(normals, pixel, 0);
    if !covered(normal) {
        textureStore(output, pixel, vec4<f32>(0.0, 0.0, 0.0, 1.0));
        return;
    }
    let emission = vec3<f32>(light.w, textureLoad(share, pixel, 0).w, normal.w);
    let shaded = emission + light.rgb * filtered_share(pixel, vec2<i32>(0, 1));
    textureStore(output, pixel, vec4<f32>(shaded, 1.0));
}
