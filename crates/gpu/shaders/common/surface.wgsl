// The surface at a shaded point, as every lighting model sees it (forward passes build it
// from the material, deferred lighting from the G-buffer).

struct Surface {
    position: vec3<f32>,
    normal: vec3<f32>,
    // The diffuse reflectance: the base colour (Blinn-Phong), the base colour of the
    // dielectric part (PBR: base colour x (1 - metallic)).
    albedo: vec3<f32>,
    alpha: f32,
    // The specular colour (Blinn-Phong) or the reflectance at normal incidence, F0 (PBR:
    // 0.04 for dielectrics, the base colour for metals, blended by metallic).
    specular: vec3<f32>,
    // The specular lobe's width: Blinn-Phong's exponent, or PBR's perceptual roughness.
    lobe: f32,
    // Radiance the surface emits itself (zero unless its material is emissive): added to
    // what the lights reflect.
    emission: vec3<f32>,
    // How far `position` may lie off the surface beyond the rasterizer's interpolation
    // (which the shadow offset's own rule covers), in world units: 0 where the position is
    // interpolated (forward passes, the full G-buffer), the reconstruction's bound where it
    // is rebuilt from depth (visibility::rebuilt_position_error). Shadow rays start
    // this much further off the surface.
    position_error: f32,
}

// The reflectance at normal incidence of glTF's dielectrics (index of refraction 1.5).
const DIELECTRIC_F0: f32 = 0.04;
