// Forward+ (clustered forward) shading: each fragment finds its cluster with the shared
// `cluster_index` and shades only that cluster's lights. With the optional depth pre-pass,
// the shading pass runs with depth test LessEqual and no depth writes, so hidden fragments
// are never shaded. Also the cluster debug views (lights-per-cluster heatmap with a legend,
// depth-slice colouring), which write display colours into the HDR target.

struct ForwardPlusParams {
    // `lights::Falloff` as FALLOFF_* in common/shading.wgsl.
    falloff: u32,
    // Light count shown as white in the heatmap.
    heatmap_max: f32,
    _pad0: u32,
    _pad1: u32,
}

// Grid description (the same as the assignment's).
@group(3) @binding(0) var<uniform> grid: ClusterParams;
// Per-cluster list offsets; offsets[cluster count] is the total.
@group(3) @binding(1) var<storage, read> offsets: array<u32>;
// The light lists, back to back.
@group(3) @binding(2) var<storage, read> light_indices: array<u32>;
// The lights.
@group(3) @binding(3) var<storage, read> lights: array<PointLight>;
// Falloff and debug scale.
@group(3) @binding(4) var<uniform> forward_plus: ForwardPlusParams;

@vertex
fn vs_main(vertex: VertexInput, @builtin(instance_index) instance_index: u32) -> VertexOutput {
    return scene_vertex(vertex, instance_index);
}

// Depth pre-pass for alpha-masked materials (opaque ones need no fragment stage).
@fragment
fn fs_depth(in: VertexOutput, @builtin(front_facing) front_facing: bool) {
    // Only for the alpha test inside.
    _ = fragment_surface(in, front_facing);
}

fn fragment_cluster(in: VertexOutput) -> u32 {
    let depth = -(view.view * vec4<f32>(in.world_position, 1.0)).z;
    return cluster_index(grid, in.clip_position.xy, depth);
}

@fragment
fn fs_main(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let surface = fragment_surface(in, front_facing);
    let view_dir = normalize(view.camera_position.xyz - surface.position);
    let cluster = fragment_cluster(in);
    let start = offsets[cluster];
    let end = min(offsets[cluster + 1u], grid.scheme_lights_capacity.z);
    var radiance = vec3<f32>(0.0);
    for (var i = start; i < end; i++) {
        radiance += shade_point_light(surface, view_dir, lights[light_indices[i]], forward_plus.falloff);
    }
    return to_hdr_target(radiance);
}

// Black -> blue -> cyan -> green -> yellow -> red -> white as t goes 0 -> 1.
fn heat_colour(t: f32) -> vec3<f32> {
    let stops = array<vec3<f32>, 7>(
        vec3<f32>(0.0, 0.0, 0.0),
        vec3<f32>(0.0, 0.0, 1.0),
        vec3<f32>(0.0, 1.0, 1.0),
        vec3<f32>(0.0, 1.0, 0.0),
        vec3<f32>(1.0, 1.0, 0.0),
        vec3<f32>(1.0, 0.0, 0.0),
        vec3<f32>(1.0, 1.0, 1.0),
    );
    let x = saturate(t) * 6.0;
    let i = min(u32(x), 5u);
    return mix(stops[i], stops[i + 1u], x - f32(i));
}

// Height of the legend strip at the bottom of the heatmap, in pixels.
const LEGEND_HEIGHT: f32 = 8.0;

@fragment
fn fs_heatmap(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let surface = fragment_surface(in, front_facing);
    let screen = grid.tile_and_screen.zw;
    // Legend: the colour scale from 0 (left) to heatmap_max (right), ticks at quarters.
    if in.clip_position.y > screen.y - LEGEND_HEIGHT {
        let t = in.clip_position.x / screen.x;
        let tick = abs(fract(t * 4.0 + 0.5) - 0.5) * screen.x / 4.0 < 1.0;
        return vec4<f32>(select(heat_colour(t), vec3<f32>(1.0), tick), 1.0);
    }
    let cluster = fragment_cluster(in);
    let count = f32(offsets[cluster + 1u] - offsets[cluster]);
    // A little shading so the geometry stays readable.
    let shade = 0.75 + 0.25 * abs(surface.normal.y);
    return vec4<f32>(heat_colour(count / forward_plus.heatmap_max) * shade, 1.0);
}

@fragment
fn fs_slices(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let surface = fragment_surface(in, front_facing);
    let depth = -(view.view * vec4<f32>(in.world_position, 1.0)).z;
    let slice = cluster_slice(grid, depth);
    // Alternating hues per slice; tiles darken in a checkerboard.
    let hue = f32(slice % 6u) / 6.0;
    let colour = heat_colour(0.15 + 0.7 * hue);
    let tile = vec2<u32>(in.clip_position.xy / grid.tile_and_screen.xy);
    let checker = select(1.0, 0.7, ((tile.x + tile.y) & 1u) == 1u);
    return vec4<f32>(colour * checker, 1.0);
}
