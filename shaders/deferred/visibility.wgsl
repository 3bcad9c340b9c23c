// The visibility buffer's raster: depth and, per pixel, which instance and which triangle
// of the scene's index buffer is seen there (Rg32Uint). No material is shaded here, so the
// pass costs what a depth pre-pass costs; alpha-masked materials sample their base colour's
// alpha and discard, as in the G-buffer pass, so masks cut out the same pixels.

#import manylights::common::scene::scene_vertex
#import manylights::deferred::visibility_geometry::pulled_vertex
#ifdef ALPHA_MASK
#ifdef BASE_COLOR_TEXTURE
#import manylights::common::variants::base_color_textured::sample_base_color
#else
#import manylights::common::variants::base_color_flat::sample_base_color
#endif
#import manylights::common::variants::alpha_mask::apply_alpha_mask
#endif

struct VisibilityVarying {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) uv: vec2<f32>,
    // The first vertex's values hold across the triangle.
    @location(1) @interpolate(flat) instance: u32,
    @location(2) @interpolate(flat) triangle: u32,
}

// Drawn non-indexed (`GpuScene::draw_pulled`): the vertex index is the position in the
// scene's index buffer, so the triangle is that over 3.
@vertex
fn vs_visibility(
    @builtin(vertex_index) index_position: u32,
    @builtin(instance_index) instance: u32,
) -> VisibilityVarying {
    let vertex = scene_vertex(pulled_vertex(index_position, instance), instance);
    var out: VisibilityVarying;
    out.clip_position = vertex.clip_position;
    out.uv = vertex.uv;
    out.instance = instance;
    out.triangle = index_position / 3u;
    return out;
}

@fragment
fn fs_visibility(in: VisibilityVarying) -> @location(0) vec2<u32> {
#ifdef ALPHA_MASK
    apply_alpha_mask(sample_base_color(in.uv).a);
#endif
    return vec2<u32>(in.instance, in.triangle);
}
