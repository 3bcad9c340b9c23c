// G-buffer layout `compact` (writing): position from the depth buffer, octahedral normal in
// two 16-bit integers, albedo in sRGB 8-bit with the lobe code in alpha, specular in
// sRGB 8-bit when the scene uses it. 4 B normal + 4 B albedo (+ 4 B specular) + 4 B depth.

#import manylights::common::surface::Surface
#import manylights::deferred::codecs::{encode_lobe, octahedral_encode, quantize_snorm16}

struct GBufferOutput {
    @location(0) normal: vec2<u32>,
    @location(1) albedo_lobe: vec4<f32>,
    @location(2) specular: vec4<f32>,
#ifdef EMISSIVE
    // Emitted radiance (EMISSION_FORMAT, HDR), only when a material of the scene emits.
    @location(3) emission: vec4<f32>,
#endif
}

fn write_gbuffer(surface: Surface) -> GBufferOutput {
    var out: GBufferOutput;
    out.normal = quantize_snorm16(octahedral_encode(surface.normal));
    // The target is sRGB: the hardware encodes rgb; alpha stays linear.
    out.albedo_lobe = vec4<f32>(surface.albedo, encode_lobe(surface.lobe));
    out.specular = vec4<f32>(surface.specular, 1.0);
#ifdef EMISSIVE
    out.emission = vec4<f32>(surface.emission, 1.0);
#endif
    return out;
}
