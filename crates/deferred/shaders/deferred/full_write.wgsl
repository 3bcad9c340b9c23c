// G-buffer layout `full` (writing): every attribute in f32, lossless. 16 B position and
// shininess + 16 B normal + 16 B albedo (+ 16 B specular when the scene uses it) + 4 B depth.

#import manylights::common::surface::Surface

struct GBufferOutput {
    @location(0) position_lobe: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) albedo: vec4<f32>,
    @location(3) specular: vec4<f32>,
#ifdef EMISSIVE
    // Emitted radiance (EMISSION_FORMAT, HDR), only when a material of the scene emits.
    @location(4) emission: vec4<f32>,
#endif
}

fn write_gbuffer(surface: Surface) -> GBufferOutput {
    var out: GBufferOutput;
    out.position_lobe = vec4<f32>(surface.position, surface.lobe);
    out.normal = vec4<f32>(surface.normal, 0.0);
    out.albedo = vec4<f32>(surface.albedo, 1.0);
    out.specular = vec4<f32>(surface.specular, 1.0);
#ifdef EMISSIVE
    out.emission = vec4<f32>(surface.emission, 1.0);
#endif
    return out;
}
