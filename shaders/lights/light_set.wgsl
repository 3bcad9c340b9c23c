// The light as stored in GPU buffers (mirrors `lights::Light`, 64 bytes, std430: each
// vec3 followed by a 4-byte field packs into 16 bytes). A point light, or a spot light: a
// point light whose emission is limited to a cone (glTF KHR_lights_punctual).

const LIGHT_POINT: u32 = #LIGHT_POINT;
const LIGHT_SPOT: u32 = #LIGHT_SPOT;

struct Light {
    // World-space position.
    position: vec3<f32>,
    // Distance beyond which the light contributes nothing (windowed falloffs only).
    radius: f32,
    // Linear RGB colour, brightest channel 1.
    color: vec3<f32>,
    // Radiant intensity: the light's radiance at 1 m (on a spot's axis) is color * intensity.
    intensity: f32,
    // Spot lights: the unit direction the cone points along (zero for point lights).
    direction: vec3<f32>,
    // LIGHT_POINT or LIGHT_SPOT.
    kind: u32,
    // Spot lights: sin^2 of the outer and inner half-angles. sin^2 rather than cos: cos of
    // a needle-thin cone rounds to 1 in f32, sin^2 keeps its precision.
    sin2_outer: f32,
    sin2_inner: f32,
    unused_a: f32,
    unused_b: f32,
}
