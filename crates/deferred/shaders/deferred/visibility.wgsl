// (The extension only lets the parser accept the builtin, which the program without
// PRIMITIVE_INDEX does not use; wgpu checks the composed module against the device.)
enable primitive_index;

// The visibility buffer's raster: depth and, per pixel, which instance and which triangle
// of the scene's index buffer is seen there (Rg32Uint). No material is shaded here;
// alpha-masked materials sample their base colour's alpha and discard, as in the G-buffer
// pass, so masks cut out the same pixels.
//
// Two ways to know the triangle: with the optional primitive-index feature
// (`PRIMITIVE_INDEX`), an indexed draw through the vertex buffers, the triangle being the
// mesh's first plus the fragment's primitive index; without it (WebGPU core), a
// non-indexed draw that fetches its vertices from storage, the triangle being the vertex
// index over 3. The second transforms every corner of every triangle (no reuse of shared
// vertices), so it costs more vertex work.

#import manylights::common::scene::scene_vertex
#ifdef PRIMITIVE_INDEX
#import manylights::common::scene::VertexInput
#import manylights::deferred::visibility_geometry::instance_first_triangle
#else
#import manylights::deferred::visibility_geometry::pulled_vertex
#endif
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

#ifdef PRIMITIVE_INDEX
@vertex
fn vs_visibility(vertex: VertexInput, @builtin(instance_index) instance: u32) -> VisibilityVarying {
    let transformed = scene_vertex(vertex, instance);
    var out: VisibilityVarying;
    out.clip_position = transformed.clip_position;
    out.uv = transformed.uv;
    out.instance = instance;
    out.triangle = instance_first_triangle(instance);
    return out;
}
#else
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
#endif

@fragment
fn fs_visibility(
    in: VisibilityVarying,
#ifdef PRIMITIVE_INDEX
    @builtin(primitive_index) primitive: u32,
#endif
) -> @location(0) vec2<u32> {
#ifdef ALPHA_MASK
    apply_alpha_mask(sample_base_color(in.uv).a);
#endif
#ifdef PRIMITIVE_INDEX
    // `triangle` holds the mesh's first triangle; the primitive index counts the draw's.
    return vec2<u32>(in.instance, in.triangle + primitive);
#else
    return vec2<u32>(in.instance, in.triangle);
#endif
}
