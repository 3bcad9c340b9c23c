// The G-buffer codecs on the GPU, for tests: each invocation runs one input through the very
// functions the G-buffer passes use (`codecs.wgsl`) and writes every intermediate result,
// so the tests check the shader itself rather than a copy of it.

#import manylights::deferred::codecs::{octahedral_encode, octahedral_decode, quantize_snorm16, dequantize_snorm16, encode_shininess, decode_shininess, linear_to_srgb, srgb_to_linear}

struct ProbeInput {
    // A unit normal (xyz) and a Blinn-Phong exponent (w).
    normal_shininess: vec4<f32>,
    // A linear colour (rgb).
    color: vec4<f32>,
}

struct ProbeOutput {
    octahedral: vec2<f32>,
    quantized: vec2<u32>,
    // The normal after the 16-bit round trip (xyz), the exponent after its code's (w).
    decoded_normal_shininess: vec4<f32>,
    // The colour encoded as sRGB (rgb), the exponent's code (w).
    srgb_shininess_code: vec4<f32>,
    // The colour after the sRGB round trip (rgb).
    linear: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> inputs: array<ProbeInput>;
@group(0) @binding(1) var<storage, read_write> outputs: array<ProbeOutput>;

@compute @workgroup_size(64)
fn probe(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&inputs) {
        return;
    }
    let input = inputs[id.x];
    var out: ProbeOutput;
    out.octahedral = octahedral_encode(input.normal_shininess.xyz);
    out.quantized = quantize_snorm16(out.octahedral);
    let code = encode_shininess(input.normal_shininess.w);
    out.decoded_normal_shininess = vec4<f32>(octahedral_decode(dequantize_snorm16(out.quantized)), decode_shininess(code));
    let srgb = linear_to_srgb(input.color.rgb);
    out.srgb_shininess_code = vec4<f32>(srgb, code);
    out.linear = vec4<f32>(srgb_to_linear(srgb), 1.0);
    outputs[id.x] = out;
}
