// The light as stored in GPU buffers (mirrors `lights::Light`, 64 bytes, std430: each
// vec3 followed by a 4-byte field packs into 16 bytes). A point light, a spot light (a
// point light whose emission is limited to a cone, glTF KHR_lights_punctual), or an area
// light: a sphere, rectangle or triangle of uniform radiance (`lights::Light` says how the
// last fields hold each shape).

const LIGHT_POINT: u32 = #LIGHT_POINT;
const LIGHT_SPOT: u32 = #LIGHT_SPOT;
const LIGHT_SPHERE: u32 = #LIGHT_SPHERE;
const LIGHT_RECT: u32 = #LIGHT_RECT;
const LIGHT_TRIANGLE: u32 = #LIGHT_TRIANGLE;

// Smallest squared distance the inverse-square law divides by (1 cm squared); see
// `lights::reference::MIN_DISTANCE_SQUARED` for its measured effect. Here, with the light,
// so that what falls off with distance (shading.wgsl, the far field's nodes) reads it
// without importing the shading model.
const MIN_DISTANCE_SQUARED: f32 = 1e-4;

struct Light {
    // World-space position.
    position: vec3<f32>,
    // Distance beyond which the light contributes nothing (windowed falloffs only).
    radius: f32,
    // Linear RGB colour, brightest channel 1.
    color: vec3<f32>,
    // Radiant intensity: the light's radiance at 1 m (on a spot's axis) is color * intensity.
    intensity: f32,
    // Spot lights: the unit direction the cone points along (zero for point lights and
    // spheres). Rectangles: the first half-edge; triangles: the first corner's offset from
    // the centroid.
    direction: vec3<f32>,
    // LIGHT_POINT, LIGHT_SPOT, LIGHT_SPHERE, LIGHT_RECT or LIGHT_TRIANGLE.
    kind: u32,
    // Spot lights: sin^2 of the outer and inner half-angles. sin^2 rather than cos: cos of
    // a needle-thin cone rounds to 1 in f32, sin^2 keeps its precision.
    // Rectangles and triangles: (sin2_outer, sin2_inner, extent) is the second half-edge
    // or corner offset.
    sin2_outer: f32,
    sin2_inner: f32,
    // Spheres: the radius.
    extent: f32,
    unused: f32,
}

// A rectangle's or triangle's second edge (`lights::Light::second_edge`).
fn second_edge(light: Light) -> vec3<f32> {
    return vec3<f32>(light.sin2_outer, light.sin2_inner, light.extent);
}

// How far an area light's farthest point lies from its position (0 for points and spots):
// the animation adds it to the reach of the light's intensity.
fn light_bounding_radius(light: Light) -> f32 {
    let second = second_edge(light);
    switch light.kind {
        case LIGHT_SPHERE: {
            return light.extent;
        }
        case LIGHT_RECT: {
            return length(light.direction + second);
        }
        case LIGHT_TRIANGLE: {
            return max(max(length(light.direction), length(second)), length(light.direction + second));
        }
        default: {
            return 0.0;
        }
    }
}
