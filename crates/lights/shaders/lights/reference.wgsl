// The full-frame reference on the GPU (`lights::GpuReference`): every light at every pixel
// of a surface capture (the data the f64 reference reads, not a G-buffer), shaded with the
// scene's BRDF by the one shading model every pipeline uses, summed with Neumaier's
// compensated summation. A dispatch adds the lights `first_light .. first_light +
// light_count` to each pixel's running sum and compensation, so a million lights are many
// short dispatches. The CPU adds sum + compensation in f64, and the surface's emission.

#import manylights::common::surface::Surface
#import manylights::lights::light_set::Light
#import manylights::lights::shading::shade_loop_light
#import manylights::lights::brdf::surface_for_loop
#import manylights::lights::reference_terms::{CompensatedSum, captured_surface, compensated_add, relative_loop_light}

struct ReferenceParams {
    // The world position the captured positions are relative to (xyz; w unused).
    origin: vec4<f32>,
    // The camera, relative to `origin` (xyz; w unused).
    camera: vec4<f32>,
    // Pixels a row, pixels in all, the first light of this dispatch, its light count.
    width: u32,
    pixels: u32,
    first_light: u32,
    light_count: u32,
    // The falloff (`lights::Falloff`'s shader mode).
    falloff: u32,
    // Always 0, but read at run time: see `reference_terms::opaque`.
    opaque_zero: u32,
    _pad: vec2<u32>,
}

@group(3) @binding(0) var<uniform> params: ReferenceParams;
// The surface capture (`gpu::SurfaceImage`): camera-relative position (w: 1 where a
// surface was drawn), normal and lobe, diffuse albedo, specular colour or F0.
@group(3) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(3) @binding(2) var<storage, read> normal_lobes: array<vec4<f32>>;
@group(3) @binding(3) var<storage, read> albedos: array<vec4<f32>>;
@group(3) @binding(4) var<storage, read> speculars: array<vec4<f32>>;
@group(3) @binding(5) var<storage, read> lights: array<Light>;
// Per pixel: the running sum (rgb) and its compensation (rgb), w unused.
@group(3) @binding(6) var<storage, read_write> sums: array<vec4<f32>>;
@group(3) @binding(7) var<storage, read_write> compensations: array<vec4<f32>>;

@compute @workgroup_size(64)
fn reference(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = id.y * params.width + id.x;
    if id.x >= params.width || pixel >= params.pixels || positions[pixel].w != 1.0 {
        return;
    }
    let position = positions[pixel];
    let surface = captured_surface(position, normal_lobes[pixel], albedos[pixel], speculars[pixel]);
    let view_dir = normalize(params.camera.xyz - position.xyz);
    let shaded = surface_for_loop(surface, view_dir);
    var running = CompensatedSum(sums[pixel].xyz, compensations[pixel].xyz);
    let end = params.first_light + params.light_count;
    for (var i = params.first_light; i < end; i++) {
        let light = relative_loop_light(lights[i], params.origin.xyz);
        running = compensated_add(running, shade_loop_light(shaded, view_dir, light, params.falloff), params.opaque_zero);
    }
    sums[pixel] = vec4<f32>(running.sum, 0.0);
    compensations[pixel] = vec4<f32>(running.compensation, 0.0);
}
