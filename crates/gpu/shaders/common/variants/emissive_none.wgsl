// Variant: no material of the scene emits light.

fn sample_emission(uv: vec2<f32>) -> vec3<f32> {
    return vec3<f32>(0.0);
}
