// The surface at a shaded point, as every lighting model sees it (forward passes build it
// from the material, deferred lighting from the G-buffer).

struct Surface {
    position: vec3<f32>,
    normal: vec3<f32>,
    albedo: vec3<f32>,
    alpha: f32,
    specular: vec3<f32>,
    shininess: f32,
}
