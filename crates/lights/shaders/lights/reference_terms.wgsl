// What the GPU references share (`lights::GpuReference`, `visibility::GpuVisibleReference`):
// a surface from the capture's attributes, a light relative to the capture's origin, and
// Neumaier's compensated sum, pinned against reassociation.

#import manylights::common::surface::Surface
#import manylights::lights::light_set::Light
#import manylights::lights::shading::{LoopLight, emitted_per_intensity}

// A captured pixel's surface (`gpu::SurfaceImage`): camera-relative position, normal and
// lobe, diffuse albedo (alpha in w), specular colour or F0.
fn captured_surface(position: vec4<f32>, normal_lobe: vec4<f32>, albedo: vec4<f32>, specular: vec4<f32>) -> Surface {
    return Surface(position.xyz, normalize(normal_lobe.xyz), albedo.rgb, albedo.a, specular.rgb, normal_lobe.w, vec3<f32>(0.0), 0.0);
}

// `light` as the shading loop takes it, its position relative to the capture's `origin`.
fn relative_loop_light(light: Light, origin: vec3<f32>) -> LoopLight {
    return LoopLight(
        light.position - origin,
        light.radius,
        light.color * light.intensity * emitted_per_intensity(light),
        1.0 / (light.radius * light.radius),
        light.direction,
        light.kind,
        light.sin2_outer,
        light.sin2_inner,
        light.extent,
    );
}

// A running f32 sum and what its additions rounded off.
struct CompensatedSum {
    sum: vec3<f32>,
    compensation: vec3<f32>,
}

// `x`, through a bit operation the compiler cannot see through. Compensated summation
// computes what rounding lost, (sum - t) + term with t = sum + term, which is zero in real
// arithmetic: a compiler allowed to reassociate (SPIR-V's float operations carry no
// `NoContraction`, and Mesa's and drivers' optimisers use that) folds or reorders it and
// loses the correction. Or-ing in a zero read at run time (a uniform's) keeps each value
// what the hardware rounded.
fn opaque(x: vec3<f32>, zero: u32) -> vec3<f32> {
    return bitcast<vec3<f32>>(bitcast<vec3<u32>>(x) | vec3<u32>(zero));
}

// `running` + `term`, Neumaier's way: what the addition rounds off, from whichever operand
// is larger, goes to the compensation. Each step is pinned (`opaque`, `zero` a run-time 0):
// reassociating any two of them loses the correction (lavapipe turned c + ((s - t) + y)
// into ((c + s) - t) + y, rounding c to s's ulp).
fn compensated_add(running: CompensatedSum, term: vec3<f32>, zero: u32) -> CompensatedSum {
    let sum = running.sum;
    let total = opaque(sum + term, zero);
    let larger = select(term, sum, abs(sum) >= abs(term));
    let smaller = select(sum, term, abs(sum) >= abs(term));
    let excess = opaque(larger - total, zero);
    let compensation = opaque(running.compensation + opaque(excess + smaller, zero), zero);
    return CompensatedSum(total, compensation);
}
