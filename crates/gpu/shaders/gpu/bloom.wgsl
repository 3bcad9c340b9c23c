// Bloom (`--bloom STRENGTH`, `gpu::bloom`): the light a lens and the eye spread around
// bright things, in compute, after temporal anti-aliasing and before the tonemap.
//
// A chain of half-size images (the "down" chain) filters the HDR frame ever wider; an
// "up" chain adds them back from the coarsest, each level a blend of its own down image
// and the coarser level tent-filtered up: U[i] = D[i] + SPREAD * (tent(U[i+1]) - D[i]).
// The frame is then blended toward U[0]: HDR + STRENGTH * (tent(U[0]) - HDR). Every step
// is a weighted mean whose weights sum to 1, so the frame's light is moved, not made:
// its total is kept (up to the frame's border, where what spreads out is lost and the
// clamped reads put some back, and the first step's firefly weighting, below).
//
// The first step (Jimenez 2014): 13 bilinear taps as five overlapping 2x2 boxes, each box
// weighted by 1 / (1 + its exposed luminance) (Karis's average), so one sub-pixel
// firefly, which TAA's jitter moves from pixel to pixel, cannot flash a whole blob of
// bloom. That weighting moves a box's weight toward its darker neighbours: it is the one
// step that does not keep the total exactly, only where neighbouring boxes differ.

#import manylights::gpu::exposure_state::ExposureState

struct BloomParams {
    // How far the frame is blended toward its bloom (0: off, 1: all bloom).
    strength: f32,
    // How much of each level is the coarser levels' (the bloom's reach).
    spread: f32,
    _pad0: f32,
    _pad1: f32,
}

// What the pass filters: the HDR frame (first step), the finer down level (down), the
// coarser up level (up, composite).
@group(0) @binding(0) var source: texture_2d<f32>;
// What the up steps blend with: this level's down image (up), the HDR frame (composite).
@group(0) @binding(1) var detail: texture_2d<f32>;
@group(0) @binding(2) var linear_clamp: sampler;
@group(0) @binding(3) var destination: texture_storage_2d<rgba16float, write>;
@group(0) @binding(4) var<uniform> params: BloomParams;
@group(0) @binding(5) var<storage, read> exposure: ExposureState;

fn luminance(rgb: vec3<f32>) -> f32 {
    return dot(rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
}

fn tap(uv: vec2<f32>, offset: vec2<f32>) -> vec3<f32> {
    let texel = 1.0 / vec2<f32>(textureDimensions(source));
    return textureSampleLevel(source, linear_clamp, uv + offset * texel, 0.0).rgb;
}

// The 13-tap downsample at `uv`: five 2x2 boxes (the centre one weighing 1/2, the four
// corner ones 1/8 each), each the mean of its four bilinear taps; `karis` weights each box
// by 1 / (1 + exposed luminance) and renormalises.
fn downsample(uv: vec2<f32>, karis: bool) -> vec3<f32> {
    let a = tap(uv, vec2<f32>(-2.0, -2.0));
    let b = tap(uv, vec2<f32>(0.0, -2.0));
    let c = tap(uv, vec2<f32>(2.0, -2.0));
    let d = tap(uv, vec2<f32>(-2.0, 0.0));
    let e = tap(uv, vec2<f32>(0.0, 0.0));
    let f = tap(uv, vec2<f32>(2.0, 0.0));
    let g = tap(uv, vec2<f32>(-2.0, 2.0));
    let h = tap(uv, vec2<f32>(0.0, 2.0));
    let i = tap(uv, vec2<f32>(2.0, 2.0));
    let j = tap(uv, vec2<f32>(-1.0, -1.0));
    let k = tap(uv, vec2<f32>(1.0, -1.0));
    let l = tap(uv, vec2<f32>(-1.0, 1.0));
    let m = tap(uv, vec2<f32>(1.0, 1.0));
    let boxes = array<vec3<f32>, 5>(
        (j + k + l + m) * 0.25,
        (a + b + d + e) * 0.25,
        (b + c + e + f) * 0.25,
        (d + e + g + h) * 0.25,
        (e + f + h + i) * 0.25,
    );
    let exposed = select(1.0, exposure.value, exposure.value > 0.0);
    var sum = vec3<f32>(0.0);
    var total = 0.0;
    for (var n = 0; n < 5; n++) {
        var weight = select(0.125, 0.5, n == 0);
        if karis {
            weight /= 1.0 + luminance(boxes[n]) * exposed;
        }
        sum += boxes[n] * weight;
        total += weight;
    }
    return sum / total;
}

// The 3x3 tent filter (1 2 1 / 2 4 2 / 1 2 1, over 16) of `source` around `uv`, one
// source texel apart.
fn tent(uv: vec2<f32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let weight = f32((2 - abs(dx)) * (2 - abs(dy)));
            sum += tap(uv, vec2<f32>(f32(dx), f32(dy))) * weight;
        }
    }
    return sum / 16.0;
}

// The destination pixel's centre as a texture coordinate, if it is in the destination.
fn destination_uv(id: vec3<u32>) -> vec2<f32> {
    return (vec2<f32>(id.xy) + 0.5) / vec2<f32>(textureDimensions(destination));
}

fn inside(id: vec3<u32>) -> bool {
    return all(id.xy < textureDimensions(destination));
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_downsample_first(@builtin(global_invocation_id) id: vec3<u32>) {
    if inside(id) {
        textureStore(destination, id.xy, vec4<f32>(downsample(destination_uv(id), true), 1.0));
    }
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    if inside(id) {
        textureStore(destination, id.xy, vec4<f32>(downsample(destination_uv(id), false), 1.0));
    }
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_upsample(@builtin(global_invocation_id) id: vec3<u32>) {
    if inside(id) {
        let own = textureLoad(detail, id.xy, 0).rgb;
        let spread = own + params.spread * (tent(destination_uv(id)) - own);
        textureStore(destination, id.xy, vec4<f32>(spread, 1.0));
    }
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_composite(@builtin(global_invocation_id) id: vec3<u32>) {
    if inside(id) {
        let frame = textureLoad(detail, id.xy, 0);
        let bloomed = frame.rgb + params.strength * (tent(destination_uv(id)) - frame.rgb);
        textureStore(destination, id.xy, vec4<f32>(bloomed, frame.a));
    }
}
