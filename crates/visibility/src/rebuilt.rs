//! How far a position rebuilt from depth may lie off the surface the rasterizer drew: the
//! layouts that store no position (`compact`, `packed`, the visibility buffer) start their
//! shadow rays this much further off the surface, or a point rebuilt a few depth ulps
//! below a floor sees the floor between it and every light (issue 46: blocks of black on
//! lit floors, acne 20 to 30 m away). `rebuilt_position_error` in
//! shaders/visibility/rebuilt.wgsl is the GPU's half; [`rebuilt_position_error`] here is its
//! f64 twin, for tests that must know which shadow rays the larger offset may decide
//! otherwise.

use glam::DMat4;
use manylights_gpu::ShaderDef;

/// Depth ulps a rebuilt position may be off by: the rasterizer's interpolation of the depth
/// plane (a few roundings of values near the pixel's depth) and the reconstruction's (the
/// inverse projection's rounded entries, its product and sum), each within one or two
/// ulps. Measured with standard Z: up to 3 on lavapipe (correlated over the 8x8 blocks its
/// rasterizer steps through, hence the 8-pixel edges) and on SwiftShader.
pub const REBUILT_DEPTH_ULPS: u32 = 8;

/// The inverse of how far, in the pixel's footprints, a rebuilt position may lie off its
/// surface where the rasterizer's depth plane is not the triangle's: it snaps vertices to
/// its sub-pixel grid (Vulkan guarantees 4 bits: a 32nd of a pixel each way) and evaluates
/// the plane from the snapped vertices, whose footprints may exceed the pixel's (a floor's
/// far corner). Measured at grazing angles, with standard and reversed Z alike: SwiftShader
/// (the page's CPU WebGPU) 1/14 of a pixel, lavapipe 1/250. An 8th leaves room, and a
/// shadow ray starting an 8th of a pixel off the surface misses only a sub-pixel contact.
pub const RASTER_PLANE_PIXELS_INVERSE: u32 = 8;

/// The constants above for rebuilt.wgsl.
pub fn shader_defs() -> Vec<(String, ShaderDef)> {
    vec![
        (
            "REBUILT_DEPTH_ULPS".to_string(),
            ShaderDef::UInt(REBUILT_DEPTH_ULPS),
        ),
        (
            "RASTER_PLANE_PIXELS_INVERSE".to_string(),
            ShaderDef::UInt(RASTER_PLANE_PIXELS_INVERSE),
        ),
    ]
}

/// The bound, in world units, for a pixel whose depth buffer holds `depth`, seen through
/// `projection` in a frame `height` pixels high, `distance` from the eye and `view_depth`
/// along the view axis: [`REBUILT_DEPTH_ULPS`] ulps of the depth turned into distance by
/// the projection's slope there, plus [`RASTER_PLANE_PIXELS_INVERSE`]'s fraction of the
/// pixel's footprint, along the view ray. With standard Z the first term grows with the
/// square of the distance (0.44 mm at 8 m with a 7 cm near plane, 4.8 cm at 100 m with a
/// 10 cm one); with reversed Z the depth's ulps shrink with it and the second dominates
/// (4.4 mm at 30 m in a 1080-pixel frame with a 65 degree field of view).
pub fn rebuilt_position_error(
    projection: DMat4,
    height: f64,
    depth: f32,
    distance: f64,
    view_depth: f64,
) -> f64 {
    let ulp = f64::from(f32::from_bits(depth.to_bits() + 1) - depth);
    // depth = (a z + b) / (c z + e) for view-space z = -view_depth (column-major).
    let (a, b) = (projection.z_axis.z, projection.w_axis.z);
    let (c, e) = (projection.z_axis.w, projection.w_axis.w);
    let w = -c * view_depth + e;
    let view_depth_per_depth = w * w / (a * e - b * c).abs();
    let footprint = 2.0 * w / (projection.y_axis.y * height);
    let along_ray = distance / view_depth.max(1e-30);
    (f64::from(REBUILT_DEPTH_ULPS) * ulp * view_depth_per_depth
        + footprint / f64::from(RASTER_PLANE_PIXELS_INVERSE))
        * along_ray
}

#[cfg(test)]
mod tests {
    use glam::{DMat4, DVec4};

    use super::rebuilt_position_error;

    /// The bound's two terms where each dominates: standard Z far away (the depth's ulps,
    /// growing with the square of the distance), and near (an 8th of a pixel's footprint).
    #[test]
    fn the_bound_follows_the_depth_precision_and_the_footprint() {
        let (near, far) = (0.1, 1000.0);
        // Right-handed, depth 0 at near and 1 at far (wgpu's), 65 degrees, 16:9.
        let f = 1.0 / 32.5f64.to_radians().tan();
        let projection = DMat4::from_cols(
            DVec4::new(f * 9.0 / 16.0, 0.0, 0.0, 0.0),
            DVec4::new(0.0, f, 0.0, 0.0),
            DVec4::new(0.0, 0.0, far / (near - far), -1.0),
            DVec4::new(0.0, 0.0, near * far / (near - far), 0.0),
        );
        let depth_at = |z: f64| {
            let clip = projection * DVec4::new(0.0, 0.0, -z, 1.0);
            (clip.z / clip.w) as f32
        };
        let error = |z: f64| rebuilt_position_error(projection, 1080.0, depth_at(z), z, z);
        // Independently: 8 ulps of the f32 depth through dz/dd = z^2 (far - near) /
        // (far near), and an 8th of the footprint 2 z tan(fov / 2) / height.
        let expected = |z: f64| {
            let depth = depth_at(z);
            let ulp = f64::from(f32::from_bits(depth.to_bits() + 1) - depth);
            let ulps = 8.0 * ulp * z * z * (far - near) / (far * near);
            let footprint = 2.0 * z * 32.5f64.to_radians().tan() / 1080.0;
            (ulps, footprint / 8.0)
        };
        for z in [1.0, 10.0, 100.0] {
            let (ulps, footprint) = expected(z);
            assert!(
                (error(z) / (ulps + footprint) - 1.0).abs() < 1e-9,
                "at {z} m: {} against {ulps} + {footprint}",
                error(z)
            );
        }
        // Near, the footprint term is nearly all of it; at 100 m the depth's ulps are more.
        assert!(expected(1.0).1 > 20.0 * expected(1.0).0);
        assert!(expected(100.0).0 > expected(100.0).1);
    }
}
