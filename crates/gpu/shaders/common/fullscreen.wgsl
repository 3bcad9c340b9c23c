// A fullscreen triangle for post-processing passes; no vertex buffers. Entry points of
// imported modules are not kept, so each fullscreen program declares
//     @vertex fn vs_fullscreen(@builtin(vertex_index) index: u32) -> FullscreenOutput
// returning `fullscreen_vertex(index)`.

struct FullscreenOutput {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

fn fullscreen_vertex(index: u32) -> FullscreenOutput {
    // One triangle covering the screen: (-1,-1), (3,-1), (-1,3).
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    var out: FullscreenOutput;
    out.position = vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
    out.uv = uv;
    return out;
}
