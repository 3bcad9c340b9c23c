// Temporal anti-aliasing (`--aa taa`, `gpu::taa`): one compute pass after the lighting
// (and the blended surfaces) and before bloom and the tonemap.
//
// Each frame's projection is moved by a sub-pixel offset (`view.jitter`, the Halton
// (2, 3) sequence), so a pixel's one sample lands at a different place in the pixel each
// frame. This pass keeps a running mean of those samples per surface point: the history
// is reprojected through last frame's camera, rejected where it saw another surface
// (`common/history.wgsl`, the rule the shadow filter uses, and a normal test), clipped to
// this frame's neighbourhood in a perceptual colour space (so light that moved, or a
// surface the rule kept by mistake, leaves no trail), then averaged with this frame's
// sample. A still camera converges to the mean of `HISTORY_FRAMES` samples spread over
// each pixel: the box-filtered image the supersampled reference is.
//
// The resolve filter: this frame's own sample unweighted (it is a sample of the pixel's
// box, as the reference's are) and the history read by a Catmull-Rom filter (5 bilinear
// taps), which keeps a moving image sharp where bilinear reads would blur it a little
// each frame. At a still camera the history is read at texel centres, exactly.

#import manylights::common::view::view
#import manylights::common::history::same_surface
#import manylights::gpu::exposure_state::ExposureState

struct TaaParams {
    // 0 on a first frame or after the history was forgotten: nothing to reproject.
    history_valid: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// This frame's HDR radiance: one jittered sample a pixel.
@group(1) @binding(0) var current: texture_2d<f32>;
@group(1) @binding(1) var depth: texture_depth_2d;
// Last frame's resolved radiance.
@group(1) @binding(2) var history: texture_2d<f32>;
// What last frame's pixels saw: the surface's distance from that frame's camera (0: the
// sky), the frames averaged, the surface's normal (octahedral).
@group(1) @binding(3) var history_surface: texture_2d<f32>;
@group(1) @binding(4) var linear_clamp: sampler;
@group(1) @binding(5) var<uniform> params: TaaParams;
// The exposure last applied: the perceptual space is that of the displayed image.
@group(1) @binding(6) var<storage, read> exposure: ExposureState;
@group(1) @binding(7) var resolved: texture_storage_2d<rgba16float, write>;
@group(1) @binding(8) var resolved_surface: texture_storage_2d<rgba32float, write>;

// The most frames the running mean averages: a full cycle of the jitter sequence, after
// which each new frame weighs 1/16.
const HISTORY_FRAMES: f32 = 16.0;
// The clipping box: the neighbourhood's mean plus or minus this many standard deviations
// in each perceptual channel (Salvi's variance clipping; 1 to 1.5 is the usual range, and
// more keeps more history at edges, where a still camera's samples vary the most).
const CLIP_SIGMAS: f32 = 1.25;
// How far from the point, in pixels, the history's sample may lie: a pixel between two
// frames' jitters, and half a pixel of rounding to the history's texel.
const HISTORY_REACH: f32 = 1.5;
// The history is rejected where the surface's normal (rebuilt from the depth) turned by
// more than 37 degrees: a crease or another object at a distance the distance rule kept.
const NORMAL_COS: f32 = 0.8;

fn luminance(rgb: vec3<f32>) -> f32 {
    return dot(rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
}

fn exposure_value() -> f32 {
    return select(1.0, exposure.value, exposure.value > 0.0);
}

// Radiance to the perceptual space the neighbourhood is measured in: exposed, compressed
// by x / (1 + luminance) (invertible, and close to how the display compresses highlights)
// and turned into YCoCg, whose axes follow the colours' natural spread.
fn perceptual(radiance: vec3<f32>, exposed: f32) -> vec3<f32> {
    let x = max(radiance, vec3<f32>(0.0)) * exposed;
    let c = x / (1.0 + luminance(x));
    return vec3<f32>(
        0.25 * c.r + 0.5 * c.g + 0.25 * c.b,
        0.5 * c.r - 0.5 * c.b,
        -0.25 * c.r + 0.5 * c.g - 0.25 * c.b,
    );
}

// The inverse of `perceptual`.
fn radiance_of(ycocg: vec3<f32>, exposed: f32) -> vec3<f32> {
    let c = max(
        vec3<f32>(ycocg.x + ycocg.y - ycocg.z, ycocg.x + ycocg.z, ycocg.x - ycocg.y - ycocg.z),
        vec3<f32>(0.0),
    );
    return c / (max(1.0 - luminance(c), 1e-3) * exposed);
}

// `value` moved toward `centre` until it lies in the box `centre` +- `extent` (exactly
// `centre` where the box is a point: a flat neighbourhood keeps no other history).
fn clip_to_box(value: vec3<f32>, centre: vec3<f32>, extent: vec3<f32>) -> vec3<f32> {
    let offset = value - centre;
    let room = extent / max(abs(offset), vec3<f32>(1e-30));
    return centre + offset * min(1.0, min(room.x, min(room.y, room.z)));
}

// The pixel centre's point in scene coordinates, homogeneous (w 0 for a point at
// infinity: the sky of an infinite projection), w made non-negative.
fn scene_point(pixel: vec2<i32>, pixel_depth: f32) -> vec4<f32> {
    let uv = (vec2<f32>(pixel) + 0.5) * view.viewport.zw;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, pixel_depth, 1.0);
    let point = view.inverse_view * (view.inverse_proj * ndc);
    return select(point, -point, point.w < 0.0);
}

fn is_sky(pixel_depth: f32) -> bool {
    return pixel_depth == view.near_far.z;
}

// The step to the neighbour at `pixel + step` or `pixel - step` whose depth is closer to
// the pixel's (the other may lie across an edge), as a tangent of the surface; zero at
// the sky or the frame's border.
fn tangent(pixel: vec2<i32>, step: vec2<i32>, point: vec3<f32>, pixel_depth: f32) -> vec3<f32> {
    let size = vec2<i32>(textureDimensions(depth));
    let ahead = clamp(pixel + step, vec2<i32>(0), size - 1);
    let behind = clamp(pixel - step, vec2<i32>(0), size - 1);
    let depth_ahead = textureLoad(depth, ahead, 0);
    let depth_behind = textureLoad(depth, behind, 0);
    let use_ahead = abs(depth_ahead - pixel_depth) <= abs(depth_behind - pixel_depth);
    let neighbour = select(behind, ahead, use_ahead);
    let neighbour_depth = select(depth_behind, depth_ahead, use_ahead);
    if is_sky(neighbour_depth) || all(neighbour == pixel) {
        return vec3<f32>(0.0);
    }
    let other = scene_point(neighbour, neighbour_depth);
    if other.w <= 0.0 {
        return vec3<f32>(0.0);
    }
    return (other.xyz / other.w - point) * select(-1.0, 1.0, use_ahead);
}

// The surface's normal rebuilt from its tangents (zero where it cannot be), facing the
// camera.
fn depth_normal(along_x: vec3<f32>, along_y: vec3<f32>, point: vec3<f32>) -> vec3<f32> {
    let across = cross(along_x, along_y);
    let length_squared = dot(across, across);
    if !(length_squared > 0.0) {
        return vec3<f32>(0.0);
    }
    let normal = across * inverseSqrt(length_squared);
    return select(normal, -normal, dot(normal, view.camera_position.xyz - point) < 0.0);
}

fn octahedral(normal: vec3<f32>) -> vec2<f32> {
    let n = normal / max(abs(normal.x) + abs(normal.y) + abs(normal.z), 1e-30);
    let folded = (1.0 - abs(n.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), n.xy >= vec2<f32>(0.0));
    return select(folded, n.xy, n.z >= 0.0);
}

fn from_octahedral(encoded: vec2<f32>) -> vec3<f32> {
    var n = vec3<f32>(encoded, 1.0 - abs(encoded.x) - abs(encoded.y));
    let t = max(-n.z, 0.0);
    n.x += select(t, -t, n.x >= 0.0);
    n.y += select(t, -t, n.y >= 0.0);
    let length_squared = dot(n, n);
    return select(vec3<f32>(0.0), n * inverseSqrt(length_squared), length_squared > 0.0);
}

// The history at `uv` through a Catmull-Rom filter: the 4x4 texels' weights, with the
// middle two of each axis merged into one bilinear tap and the four corner taps (whose
// weights are the smallest) left out, then renormalised.
fn history_at(uv: vec2<f32>) -> vec3<f32> {
    let size = view.viewport.xy;
    let at = uv * size;
    let centre = floor(at - 0.5) + 0.5;
    let f = at - centre;
    let w0 = f * (-0.5 + f * (1.0 - 0.5 * f));
    let w1 = 1.0 + f * f * (-2.5 + 1.5 * f);
    let w2 = f * (0.5 + f * (2.0 - 1.5 * f));
    let w3 = f * f * (-0.5 + 0.5 * f);
    let w12 = w1 + w2;
    let t0 = (centre - 1.0) * view.viewport.zw;
    let t3 = (centre + 2.0) * view.viewport.zw;
    let t12 = (centre + w2 / w12) * view.viewport.zw;
    let weights = array<f32, 5>(
        w12.x * w0.y, w0.x * w12.y, w12.x * w12.y, w3.x * w12.y, w12.x * w3.y,
    );
    let taps = array<vec2<f32>, 5>(
        vec2<f32>(t12.x, t0.y),
        vec2<f32>(t0.x, t12.y),
        t12,
        vec2<f32>(t3.x, t12.y),
        vec2<f32>(t12.x, t3.y),
    );
    var sum = vec3<f32>(0.0);
    var total = 0.0;
    for (var i = 0; i < 5; i++) {
        sum += textureSampleLevel(history, linear_clamp, taps[i], 0.0).rgb * weights[i];
        total += weights[i];
    }
    return max(sum / total, vec3<f32>(0.0));
}

// The frames the history averaged for the surface at `expected` from last frame's camera
// with `normal`, if one of the 3x3 history texels around `texel` saw it (0 if none did).
// The texel's neighbours count too: at an edge, the pixel's jittered samples fall on
// either side from frame to frame, so the texel itself may have seen the other surface.
fn history_of_surface(texel: vec2<i32>, expected: f32, slack: f32, normal: vec3<f32>) -> f32 {
    let size = vec2<i32>(textureDimensions(history_surface));
    var frames = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let at = clamp(texel + vec2<i32>(dx, dy), vec2<i32>(0), size - 1);
            let seen = textureLoad(history_surface, at, 0);
            // A normal either frame could not rebuild does not count against the history.
            let normal_kept = dot(normal, normal) == 0.0 || seen.z > 1.5
                || dot(normal, from_octahedral(seen.zw)) >= NORMAL_COS;
            if seen.y > 0.0 && same_surface(seen.x, expected, slack) && normal_kept {
                frames = max(frames, seen.y);
            }
        }
    }
    return frames;
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(current));
    let pixel = vec2<i32>(id.xy);
    if any(pixel >= size) {
        return;
    }
    let exposed = exposure_value();
    let sample = textureLoad(current, pixel, 0);

    // The neighbourhood's mean and spread, in the perceptual space.
    var sum = vec3<f32>(0.0);
    var sum_squares = vec3<f32>(0.0);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let at = clamp(pixel + vec2<i32>(dx, dy), vec2<i32>(0), size - 1);
            let p = perceptual(textureLoad(current, at, 0).rgb, exposed);
            sum += p;
            sum_squares += p * p;
        }
    }
    let mean = sum / 9.0;
    let spread = sqrt(max(sum_squares / 9.0 - mean * mean, vec3<f32>(0.0)));

    // What this pixel sees.
    let pixel_depth = textureLoad(depth, pixel, 0);
    let sky = is_sky(pixel_depth);
    let here = scene_point(pixel, pixel_depth);
    let finite = !sky && here.w > 0.0;
    let point = select(vec3<f32>(0.0), here.xyz / here.w, finite);
    var along_x = vec3<f32>(0.0);
    var along_y = vec3<f32>(0.0);
    if finite {
        along_x = tangent(pixel, vec2<i32>(1, 0), point, pixel_depth);
        along_y = tangent(pixel, vec2<i32>(0, 1), point, pixel_depth);
    }
    let normal = depth_normal(along_x, along_y, point);

    // Where it was last frame, on last frame's resolved (unjittered) image: last frame's
    // jittered projection less its jitter, plus this frame's, so that a still camera
    // reads its history at the pixel's own centre.
    var kept = sample.rgb;
    var frames = 0.0;
    let previous_clip = view.previous_view_proj * here;
    if params.history_valid != 0u && previous_clip.w > 0.0 {
        let ndc = previous_clip.xy / previous_clip.w - view.jitter.zw + view.jitter.xy;
        let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
        if all(uv >= vec2<f32>(0.0)) && all(uv < vec2<f32>(1.0)) {
            let from_camera = point - view.previous_camera_position.xyz;
            let expected = select(0.0, length(from_camera), finite);
            // The history's sample lies up to a pixel and a half from the point (the two
            // frames' jitters and the texel's rounding): the distance may move by that much
            // of its change across a pixel of this surface.
            let ray = from_camera / max(expected, 1e-30);
            let slack = HISTORY_REACH * max(abs(dot(along_x, ray)), abs(dot(along_y, ray)));
            let seen_frames = history_of_surface(
                vec2<i32>(floor(uv * view.viewport.xy)),
                expected,
                slack,
                normal,
            );
            if seen_frames > 0.0 {
                frames = seen_frames;
                let clipped = clip_to_box(perceptual(history_at(uv), exposed), mean, CLIP_SIGMAS * spread);
                kept = radiance_of(clipped, exposed);
            }
        }
    }
    frames = min(frames + 1.0, HISTORY_FRAMES);
    // Written as history plus a step, so a pixel whose samples all agree stays exactly
    // that value.
    let accumulated = kept + (sample.rgb - kept) / frames;

    textureStore(resolved, pixel, vec4<f32>(accumulated, sample.a));
    let camera_distance = select(0.0, distance(point, view.camera_position.xyz), finite);
    // (2, 2), outside the octahedral square: no normal.
    let encoded = select(vec2<f32>(2.0), octahedral(normal), dot(normal, normal) > 0.0);
    textureStore(resolved_surface, pixel, vec4<f32>(camera_distance, frames, encoded));
}
