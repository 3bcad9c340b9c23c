// The spatial filter of the shadow rays' visible share (`visibility::Shadows::RaysSpatial`),
// after deferred's compute lighting or the forward pipelines' shadow pass
// (visibility/shadow_trace.wgsl): two compute passes over 8x8 tiles, along rows
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
// With temporal accumulation (`Shadows::RaysTemporal`), `cs_columns_temporal` takes the
// columns pass's place: it blends the filtered share with the pixel's history, found where
// the surface was a frame ago (`view.previous_view_proj`), and writes the history for the
// next frame. History is dropped where the surface seen there is another (its distance
// from last frame's camera differs) or where the pixel's unshadowed light changed by more
// than `LIGHT_CHANGE` (a light switched on or off, or moved much): as the unshadowed sum
// is exact, this test has no noise, and a light that changes the sum by less changes the
// share by about as little. Lights that move behind an occluder while their unshadowed
// light stays put are caught by holding the history within `HISTORY_MARGIN` of this
// frame's filtered share.
//
// Unfiltered (a forward pipeline's `rays:1`), `cs_compose` writes the HDR target from the
// traced share as it is.
//
// The lighting pass's emission rides in the inputs' fourth channels (r, g, b in the
// unshadowed radiance's, the share's and the normal's): its output group has room for
// four storage textures, WebGPU's guarantee, and the HDR target is the fourth.

#import manylights::common::view::view
#import manylights::visibility::rebuilt::position_from_depth
#import manylights::common::history::same_surface

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

// The history of `cs_columns_temporal`: last frame's (share in rgb, frames averaged in w;
// distance from its camera and unshadowed luminance), and this frame's, written.
@group(1) @binding(5) var previous_history: texture_2d<f32>;
@group(1) @binding(6) var previous_surface: texture_2d<f32>;
@group(1) @binding(7) var history: texture_storage_2d<rgba32float, write>;
@group(1) @binding(8) var surface: texture_storage_2d<rg32float, write>;

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

// The HDR target at `pixel`: the emission plus the unshadowed radiance times `visible`
// (the share, filtered or not); the clear colour without a surface.
fn store_shaded(pixel: vec2<i32>, visible: vec3<f32>) {
    let light = textureLoad(unshadowed, pixel, 0);
    let normal = textureLoad(normals, pixel, 0);
    if !covered(normal) {
        textureStore(output, pixel, vec4<f32>(0.0, 0.0, 0.0, 1.0));
        return;
    }
    let emission = vec3<f32>(light.w, textureLoad(share, pixel, 0).w, normal.w);
    textureStore(output, pixel, vec4<f32>(emission + light.rgb * visible, 1.0));
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_columns(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = vec2<i32>(id.xy);
    if any(pixel >= vec2<i32>(textureDimensions(share))) {
        return;
    }
    store_shaded(pixel, filtered_share(pixel, vec2<i32>(0, 1)));
}

// Unfiltered: the traced share as it is.
@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_compose(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = vec2<i32>(id.xy);
    if any(pixel >= vec2<i32>(textureDimensions(share))) {
        return;
    }
    store_shaded(pixel, textureLoad(share, pixel, 0).rgb);
}

// The most frames the history averages (`visibility::SHADOW_HISTORY_FRAMES`): a new
// frame's share weighs at least 1/16.
const HISTORY_FRAMES: f32 = 16.0;
// A change of the pixel's unshadowed luminance above 5% drops the history.
const LIGHT_CHANGE: f32 = 0.05;
// The history may differ from this frame's filtered share by at most this much: the
// filtered share's noise with one ray (a standard deviation of about 0.05 over Sponza)
// rarely reaches it, and a change of visibility larger than it shows in one frame.
const HISTORY_MARGIN: f32 = 0.15;

fn luminance(rgb: vec3<f32>) -> f32 {
    return dot(rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// Where `position` (this frame's scene coordinates) was on last frame's screen, if on it.
fn previous_pixel(position: vec3<f32>) -> vec2<i32> {
    let clip = view.previous_view_proj * vec4<f32>(position, 1.0);
    if clip.w <= 0.0 {
        return vec2<i32>(-1);
    }
    let ndc = clip.xy / clip.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    return vec2<i32>(floor(uv * view.viewport.xy));
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_columns_temporal(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = vec2<i32>(id.xy);
    let size = vec2<i32>(textureDimensions(share));
    if any(pixel >= size) {
        return;
    }
    let light = textureLoad(unshadowed, pixel, 0);
    let normal = textureLoad(normals, pixel, 0);
    if !covered(normal) {
        textureStore(output, pixel, vec4<f32>(0.0, 0.0, 0.0, 1.0));
        textureStore(history, pixel, vec4<f32>(0.0));
        textureStore(surface, pixel, vec4<f32>(0.0));
        return;
    }
    let filtered = filtered_share(pixel, vec2<i32>(0, 1));
    let position = position_from_depth(pixel, textureLoad(depth, pixel, 0)).xyz;
    let brightness = luminance(light.rgb);

    // The history, if it is of this surface under about the same unshadowed light.
    var frames = 0.0;
    var kept = filtered;
    let before = previous_pixel(position);
    if all(before >= vec2<i32>(0)) && all(before < size) {
        let previous = textureLoad(previous_history, before, 0);
        let seen = textureLoad(previous_surface, before, 0).xy;
        let expected = distance(position, view.previous_camera_position.xyz);
        let surface_kept = same_surface(seen.x, expected, 0.0);
        let same_light = abs(seen.y - brightness) <= LIGHT_CHANGE * max(seen.y, brightness);
        if previous.w > 0.0 && surface_kept && same_light {
            frames = previous.w;
            kept = clamp(previous.rgb, filtered - HISTORY_MARGIN, filtered + HISTORY_MARGIN);
        }
    }
    frames = min(frames + 1.0, HISTORY_FRAMES);
    // Written as history plus a step, so a share of exactly 1 in both stays exactly 1.
    let accumulated = kept + (filtered - kept) / frames;

    let emission = vec3<f32>(light.w, textureLoad(share, pixel, 0).w, normal.w);
    textureStore(output, pixel, vec4<f32>(emission + light.rgb * accumulated, 1.0));
    textureStore(history, pixel, vec4<f32>(accumulated, frames));
    let camera_distance = distance(position, view.camera_position.xyz);
    textureStore(surface, pixel, vec4<f32>(camera_distance, brightness, 0.0, 0.0));
}
