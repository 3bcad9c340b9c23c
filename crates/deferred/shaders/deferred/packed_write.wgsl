// G-buffer layout `packed` (writing): one Rgba32Uint target plus depth, 16 B + 4 B.
//   x: albedo sRGB 8:8:8, lobe code 8 (`codecs::encode_lobe`)
//   y: octahedral normal 16:16
//   z: specular sRGB 8:8:8, unused 8
//   w: unused

#import manylights::common::surface::Surface
#import manylights::deferred::codecs::{encode_lobe, linear_to_srgb, octahedral_encode, quantize_snorm16}

struct GBufferOutput {
    @location(0) packed: vec4<u32>,
#ifdef EMISSIVE
    // Emitted radiance (EMISSION_FORMAT, HDR), only when a material of the scene emits.
    @location(1) emission: vec4<f32>,
#endif
}

fn write_gbuffer(surface: Surface) -> GBufferOutput {
    let normal = quantize_snorm16(octahedral_encode(surface.normal));
    var out: GBufferOutput;
    out.packed = vec4<u32>(
        pack4x8unorm(vec4<f32>(linear_to_srgb(surface.albedo), encode_lobe(surface.lobe))),
        normal.x | (normal.y << 16u),
        pack4x8unorm(vec4<f32>(linear_to_srgb(surface.specular), 0.0)),
        0u,
    );
#ifdef EMISSIVE
    out.emission = vec4<f32>(surface.emission, 1.0);
#endif
    return out;
}
