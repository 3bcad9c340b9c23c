// G-buffer layout `compact` (reading).

#import manylights::deferred::codecs::{GBufferSample, decode_lobe, dequantize_snorm16, octahedral_decode, sample_from_depth}

// Whether the scene has a specular channel (else a 1x1 placeholder is bound and unread).
// (Pipeline constant 0: naga_oil renames the items of imported modules, so the pipeline
// sets it by id, `deferred::GBUFFER_SPECULAR_ID`.)
@id(0) override GBUFFER_SPECULAR: bool = true;

// Octahedral normal, 16 bits per component.
@group(1) @binding(0) var gbuffer_normal: texture_2d<u32>;
// Albedo (sRGB, decoded on load) and lobe code (`codecs::encode_lobe`).
@group(1) @binding(1) var gbuffer_albedo: texture_2d<f32>;
// Specular colour (sRGB, decoded on load).
@group(1) @binding(2) var gbuffer_specular: texture_2d<f32>;
// Depth: coverage and position.
@group(1) @binding(4) var gbuffer_depth: texture_depth_2d;

fn read_gbuffer(pixel: vec2<i32>) -> GBufferSample {
    var sample = sample_from_depth(pixel, textureLoad(gbuffer_depth, pixel, 0));
    sample.surface.normal = octahedral_decode(dequantize_snorm16(textureLoad(gbuffer_normal, pixel, 0).xy));
    let albedo = textureLoad(gbuffer_albedo, pixel, 0);
    sample.surface.albedo = albedo.rgb;
    sample.surface.lobe = decode_lobe(albedo.a);
    sample.surface.specular = vec3<f32>(0.0);
    if GBUFFER_SPECULAR {
        sample.surface.specular = textureLoad(gbuffer_specular, pixel, 0).rgb;
    }
    return sample;
}
