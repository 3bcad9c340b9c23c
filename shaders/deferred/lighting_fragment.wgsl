// Deferred lighting as a fullscreen fragment pass into the HDR target.

@fragment
fn fs_lighting(in: FullscreenOutput) -> @location(0) vec4<f32> {
    return deferred_pixel(vec2<u32>(in.position.xy));
}
