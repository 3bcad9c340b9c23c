// The surface at a shaded point, as every lighting model sees it (forward passes build it
// from the material, deferred lighting from the G-buffer).

struct Surface {
    position: vec3<f32>,
    normal: vec3<f32>,
    albedo: vec3<f32>,
    alpha: f32,
    specular: vec3<f32>,
    shininess: f32,
    // Radiance the surface emits itself (zero unless its material is emissive): added to
    // what the lights reflect.
    emission: vec3<f32>,
    // How far `position` may lie off the surface beyond the rasterizer's interpolation
    // (which the shadow offset's own rule covers), in world units: 0 where the position is
    // interpolated (forward passes, the full G-buffer), the reconstruction's bound where it
    // is rebuilt from depth (deferred::codecs::rebuilt_position_error). Shadow rays start
    // this much further off the surface.
    position_error: f32,
}
