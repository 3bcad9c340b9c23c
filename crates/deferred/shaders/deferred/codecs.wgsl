// Encodings of the G-buffer layouts (Rust twins and their tests: `deferred::codecs`).
// Octahedral normals: Meyer et al. 2010, "On floating-point normal vectors"; Cigolle et al.
// 2014, "A Survey of Efficient Representations for Independent Unit Vectors".

#import manylights::common::view::view
#import manylights::common::surface::Surface
#import manylights::visibility::rebuilt::{position_from_depth, rebuilt_position_error}

// Unit vector -> square [-1, 1]^2 (upper hemisphere in the diamond, lower folded out).
fn octahedral_encode(n: vec3<f32>) -> vec2<f32> {
    let p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if n.z >= 0.0 {
        return p;
    }
    let sign = select(vec2<f32>(-1.0), vec2<f32>(1.0), p >= vec2<f32>(0.0));
    return (1.0 - abs(p.yx)) * sign;
}

fn octahedral_decode(e: vec2<f32>) -> vec3<f32> {
    var n = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    let fold = max(-n.z, 0.0);
    n.x += select(fold, -fold, n.x >= 0.0);
    n.y += select(fold, -fold, n.y >= 0.0);
    return normalize(n);
}

// [-1, 1]^2 <-> two integers 0..=65534 with 0 at 32767, so -1, 0 and 1 (the poles and
// seams of the octahedral map) are exact.
fn quantize_snorm16(v: vec2<f32>) -> vec2<u32> {
    return vec2<u32>(vec2<i32>(round(clamp(v, vec2<f32>(-1.0), vec2<f32>(1.0)) * 32767.0)) + vec2<i32>(32767));
}

fn dequantize_snorm16(q: vec2<u32>) -> vec2<f32> {
    return (vec2<f32>(q) - 32767.0) / 32767.0;
}

// Blinn-Phong exponents 1..2048 on a log scale in [0, 1] (8 bits: 4.4% steps).
const MAX_SHININESS_LOG2: f32 = 11.0;

fn encode_shininess(shininess: f32) -> f32 {
    return log2(clamp(shininess, 1.0, 2048.0)) / MAX_SHININESS_LOG2;
}

fn decode_shininess(code: f32) -> f32 {
    return exp2(code * MAX_SHININESS_LOG2);
}

// A surface's lobe (`Surface::lobe`) as an 8-bit code in [0, 1]: PBR's perceptual
// roughness as it is (0.4% steps; glTF stores it in 8 bits too), Blinn-Phong's exponent on
// the log scale above.
fn encode_lobe(lobe: f32) -> f32 {
#ifdef SHADING_PBR
    return saturate(lobe);
#else
    return encode_shininess(lobe);
#endif
}

fn decode_lobe(code: f32) -> f32 {
#ifdef SHADING_PBR
    return code;
#else
    return decode_shininess(code);
#endif
}

// The sRGB transfer function (for layouts that pack 8-bit colour by hand).
fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = saturate(c);
    return select(1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055, x * 12.92, x <= vec3<f32>(0.0031308));
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
}

// What the lighting pass reads back for a pixel.
struct GBufferSample {
    surface: Surface,
    // Positive view-space distance along -Z.
    view_depth: f32,
    // False where no geometry was drawn.
    covered: bool,
}

// The part of a sample that layouts storing no position share: coverage, position and view
// depth from the depth buffer; opaque.
fn sample_from_depth(pixel: vec2<i32>, depth: f32) -> GBufferSample {
    var sample: GBufferSample;
    sample.covered = depth != view.near_far.z;
    let position = position_from_depth(pixel, depth);
    sample.surface.position = position.xyz;
    sample.view_depth = position.w;
    sample.surface.alpha = 1.0;
#ifdef LIGHT_LOOP_SHADOWS
    sample.surface.position_error = rebuilt_position_error(depth, position.xyz - view.camera_position.xyz, position.w);
#endif
    return sample;
}

