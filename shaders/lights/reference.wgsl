// The full-frame reference on the GPU (`lights::GpuReference`): every light at every pixel
// of a surface capture (the data the f64 reference reads, not a G-buffer), shaded with the
// scene's BRDF by the one shading model every pipeline uses, summed with Neumaier's
// compensated summation. A dispatch adds the lights `first_light .. first_light +
// light_count` to each pixel's running sum and compensation, so a million lights are many
// short dispatches. The CPU adds sum + compensation in f64, and the surface's emission.

#import manylights::common::surface::Surface
#import manylights::lights::light_set::Light
#import manylights::lights::shading::{LoopLight, shade_loop_light, surface_for_loop}

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
    // Always 0, but read at run time: see `opaque`.
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

// `x`, through a bit operation the compiler cannot see through. Compensated summation
// computes what rounding lost, (sum - t) + term with t = sum + term, which is zero in real
// arithmetic: a compiler allowed to reassociate (SPIR-V's float operations carry no
// `NoContraction`, and Mesa's and drivers' optimisers use that) folds or reorders it and
// loses the correction. Or-ing in a zero read from a uniform keeps each value what the
// hardware rounded.
fn opaque(x: vec3<f32>, zero: u32) -> vec3<f32> {
    return bitcast<vec3<f32>>(bitcast<vec3<u32>>(x) | vec3<u32>(zero));
}

@compute @workgroup_size(64)
fn reference(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = id.y * params.width + id.x;
    if id.x >= params.width || pixel >= params.pixels || positions[pixel].w != 1.0 {
        return;
    }
    let normal_lobe = normal_lobes[pixel];
    let albedo = albedos[pixel];
    let specular = speculars[pixel];
    let position = positions[pixel].xyz;
    var surface = Surface(position, normalize(normal_lobe.xyz), albedo.rgb, albedo.a, specular.rgb, normal_lobe.w, vec3<f32>(0.0), 0.0);
    let view_dir = normalize(params.camera.xyz - position);
    surface = surface_for_loop(surface, view_dir);
    let zero = bitcast<u32>(sums[pixel].w);
    var sum = sums[pixel].xyz;
    var compensation = compensations[pixel].xyz;
    let end = params.first_light + params.light_count;
    for (var i = params.first_light; i < end; i++) {
        let light = lights[i];
        let loop_light = LoopLight(
            light.position - params.origin.xyz,
            light.radius,
            light.color * light.intensity,
            1.0 / (light.radius * light.radius),
            light.direction,
            light.kind,
            light.sin2_outer,
            light.sin2_inner,
        );
        let term = shade_loop_light(surface, view_dir, loop_light, params.falloff);
        // Neumaier: what the addition rounds off, from whichever operand is larger. Each
        // step is pinned (`opaque`): reassociating any two of them loses the correction
        // (lavapipe turned c + ((s - t) + y) into ((c + s) - t) + y, rounding c to s's ulp).
        let total = opaque(sum + term, zero);
        let larger = select(term, sum, abs(sum) >= abs(term));
        let smaller = select(sum, term, abs(sum) >= abs(term));
        let excess = opaque(larger - total, zero);
        compensation = opaque(compensation + opaque(excess + smaller, zero), zero);
        sum = total;
    }
    sums[pixel] = vec4<f32>(sum, 0.0);
    compensations[pixel] = vec4<f32>(compensation, 0.0);
}
