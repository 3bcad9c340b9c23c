// The visibility buffer's resolve: one dispatch per material over the tiles it covers
// (`visibility_classify.wgsl`), with that material's bind group. Each pixel of the
// material rebuilds its surface from its instance and triangle: the triangle's three
// vertices through the raster's own vertex transform, perspective-correct barycentrics of
// the pixel's centre, and the UV's rate across its 2x2 quad for the mip level, then
// the material as the G-buffer pass samples it, written in the `packed` layout that
// lighting reads.

#import manylights::common::view::view
#import manylights::common::scene::{VertexOutput, scene_vertex}
#import manylights::common::material::fragment_surface
#import manylights::common::material_bindings::uv_gradients
#import manylights::deferred::packed_write::write_gbuffer
#import manylights::deferred::visibility_geometry::{instance_material, pulled_vertex}

// (Group 1 binding 0 is the scene's instance transforms, `scene.wgsl`.)
@group(1) @binding(1) var visibility: texture_2d<u32>;
@group(1) @binding(2) var<storage, read> material_tiles: array<MaterialTiles>;
@group(1) @binding(3) var<storage, read> tile_list: array<u32>;
@group(1) @binding(4) var gbuffer_packed: texture_storage_2d<rgba32uint, write>;
#ifdef EMISSIVE
@group(1) @binding(5) var gbuffer_emission: texture_storage_2d<rgba16float, write>;
#endif
// Which material this dispatch resolves (a dynamic offset per material).
@group(1) @binding(6) var<uniform> resolve: ResolveMaterial;

struct ResolveMaterial {
    material: u32,
}

// `visibility_classify.wgsl`'s record, read only.
struct MaterialTiles {
    tile_count: u32,
    dispatch_y: u32,
    dispatch_z: u32,
    first: u32,
    filled: u32,
    // Pads the record to 32 bytes (a vec3 here would align to 16 and make it 48).
    padding: array<u32, 3>,
}

// The point of a triangle seen through the NDC point `ndc`, as barycentric weights that
// interpolate attributes perspective-correctly. Homogeneous: with a triangle's clip-space
// (x, y, w) as the columns of M, the point seen through (ndc, 1) is M b for b along
// M^-1 (ndc, 1), whose rows are the cross products of the other two columns; normalised
// to sum 1. No divide by w, so triangles through the near plane need no clipping.
fn perspective_barycentrics(clip: array<vec3<f32>, 3>, ndc: vec2<f32>) -> vec3<f32> {
    let ray = vec3<f32>(ndc, 1.0);
    let weights = vec3<f32>(
        dot(cross(clip[1], clip[2]), ray),
        dot(cross(clip[2], clip[0]), ray),
        dot(cross(clip[0], clip[1]), ray),
    );
    return weights / (weights.x + weights.y + weights.z);
}

fn interpolate2(b: vec3<f32>, a: array<vec2<f32>, 3>) -> vec2<f32> {
    return b.x * a[0] + b.y * a[1] + b.z * a[2];
}

fn interpolate3(b: vec3<f32>, a: array<vec3<f32>, 3>) -> vec3<f32> {
    return b.x * a[0] + b.y * a[1] + b.z * a[2];
}

fn interpolate4(b: vec3<f32>, a: array<vec4<f32>, 3>) -> vec4<f32> {
    return b.x * a[0] + b.y * a[1] + b.z * a[2];
}

// What a fragment of the G-buffer pass would have received at `pixel`, where the raster
// saw triangle `triangle` of `instance`.
struct RebuiltFragment {
    inputs: VertexOutput,
    // Counter-clockwise on screen (the pipelines' front face): the sign of the clip-space
    // (x, y, w) determinant.
    front_facing: bool,
}

fn rebuild_fragment(pixel: vec2<u32>, instance: u32, triangle: u32) -> RebuiltFragment {
    var corners: array<VertexOutput, 3>;
    for (var corner = 0u; corner < 3u; corner += 1u) {
        corners[corner] = scene_vertex(pulled_vertex(3u * triangle + corner, instance), instance);
    }
    let clip = array<vec3<f32>, 3>(corners[0].clip_position.xyw, corners[1].clip_position.xyw, corners[2].clip_position.xyw);
    // The pixel's centre in NDC (y up), and one pixel's step.
    let ndc = (vec2<f32>(pixel) + 0.5) * view.viewport.zw * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    let ndc_step = 2.0 * view.viewport.zw;
    // Derivatives as a fragment shader's 2x2 quad takes them for its implicit mip level:
    // coarse, one per quad, the top row's difference across and the left column's down
    // (what llvmpipe does; Vulkan lets a device take them per row and column instead,
    // which differs by the rate's change over one pixel). Forward differences at every
    // pixel would be backward ones' mirror at odd rows and columns and pick other mip
    // levels where the rate changes fast (a textured floor at a grazing angle).
    let quad_corner = vec2<f32>(pixel & vec2<u32>(~1u));
    let ndc_corner = (quad_corner + 0.5) * view.viewport.zw * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    let b = perspective_barycentrics(clip, ndc);
    let b_corner = perspective_barycentrics(clip, ndc_corner);
    let b_across = perspective_barycentrics(clip, ndc_corner + vec2<f32>(ndc_step.x, 0.0));
    let b_down = perspective_barycentrics(clip, ndc_corner - vec2<f32>(0.0, ndc_step.y));
    let uvs = array<vec2<f32>, 3>(corners[0].uv, corners[1].uv, corners[2].uv);
    var fragment: RebuiltFragment;
    fragment.inputs.world_position = interpolate3(b, array<vec3<f32>, 3>(corners[0].world_position, corners[1].world_position, corners[2].world_position));
    fragment.inputs.world_normal = interpolate3(b, array<vec3<f32>, 3>(corners[0].world_normal, corners[1].world_normal, corners[2].world_normal));
    fragment.inputs.world_tangent = interpolate4(b, array<vec4<f32>, 3>(corners[0].world_tangent, corners[1].world_tangent, corners[2].world_tangent));
    fragment.inputs.uv = interpolate2(b, uvs);
    let uv_corner = interpolate2(b_corner, uvs);
    uv_gradients = vec4<f32>(interpolate2(b_across, uvs) - uv_corner, interpolate2(b_down, uvs) - uv_corner);
    fragment.front_facing = dot(clip[0], cross(clip[1], clip[2])) > 0.0;
    return fragment;
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_resolve(
    @builtin(workgroup_id) workgroup: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
) {
    let tile_word = tile_list[material_tiles[resolve.material].first + workgroup.x];
    let pixel = vec2<u32>(tile_word & 0xffffu, tile_word >> 16u) * #SCREEN_TILE + local.xy;
    if any(pixel >= textureDimensions(visibility)) {
        return;
    }
    let seen = textureLoad(visibility, pixel, 0).xy;
    // Lighting never reads uncovered pixels (coverage comes from depth); other materials'
    // pixels of the tile are resolved by their own dispatches.
    if seen.x == 0xffffffffu || instance_material(seen.x) != resolve.material {
        return;
    }
    let fragment = rebuild_fragment(pixel, seen.x, seen.y);
    let surface = fragment_surface(fragment.inputs, fragment.front_facing);
    let written = write_gbuffer(surface);
    textureStore(gbuffer_packed, pixel, written.packed);
#ifdef EMISSIVE
    textureStore(gbuffer_emission, pixel, written.emission);
#endif
}
