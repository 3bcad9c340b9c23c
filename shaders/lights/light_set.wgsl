// The point light as stored in GPU buffers (mirrors `lights::PointLight`, 32 bytes,
// std430: a vec3 followed by an f32 packs into 16 bytes).

struct PointLight {
    // World-space position.
    position: vec3<f32>,
    // Distance beyond which the light contributes nothing (windowed falloffs only).
    radius: f32,
    // Linear RGB colour, brightest channel 1.
    color: vec3<f32>,
    // Radiant intensity: the light's radiance at 1 m is color * intensity.
    intensity: f32,
}
