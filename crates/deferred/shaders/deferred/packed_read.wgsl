// G-buffer layout `packed` (reading).

#import manylights::deferred::codecs::{GBufferSample, decode_lobe, dequantize_snorm16, octahedral_decode, sample_from_depth, srgb_to_linear}

// The packed attributes (see packed_write.wgsl).
@group(1) @binding(0) var gbuffer_packed: texture_2d<u32>;
// Depth: coverage and position.
@group(1) @binding(4) var gbuffer_depth: texture_depth_2d;

fn read_gbuffer(pixel: vec2<i32>) -> GBufferSample {
    var sample = sample_from_depth(pixel, textureLoad(gbuffer_depth, pixel, 0));
    let packed = textureLoad(gbuffer_packed, pixel, 0);
    let albedo = unpack4x8unorm(packed.x);
    sample.surface.albedo = srgb_to_linear(albedo.rgb);
    sample.surface.lobe = decode_lobe(albedo.a);
    sample.surface.normal = octahedral_decode(dequantize_snorm16(vec2<u32>(packed.y & 0xffffu, packed.y >> 16u)));
    sample.surface.specular = srgb_to_linear(unpack4x8unorm(packed.z).rgb);
    return sample;
}
