//! The per-frame camera uniform (`shaders/common/view.wgsl`), bound at group 0.

use glam::{Mat4, Vec3};

use crate::context::GpuContext;
use crate::depth::DepthConvention;
use crate::error::{GpuError, GpuResult};

/// Mirrors `struct View` in `shaders/common/view.wgsl` (std140-compatible: only mat4 and vec4).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ViewUniform {
    pub view_proj: [[f32; 4]; 4],
    pub view: [[f32; 4]; 4],
    pub proj: [[f32; 4]; 4],
    pub inverse_proj: [[f32; 4]; 4],
    pub inverse_view: [[f32; 4]; 4],
    pub camera_position: [f32; 4],
    pub viewport: [f32; 4],
    pub near_far: [f32; 4],
    /// World position the scene's coordinates are relative to (xyz; w unused).
    pub origin: [f32; 4],
    /// The frame's seeds: x, the stochastic shadow rays' (`ShadowSettings::seed`);
    /// the rest unused.
    pub seeds: [u32; 4],
    /// The previous frame's world to clip space, taking this frame's scene coordinates
    /// (relative to this frame's `origin`): where a surface was on the screen a frame ago,
    /// for passes that reuse history (the shadow rays' temporal accumulation). The
    /// current `view_proj` on a first frame.
    pub previous_view_proj: [[f32; 4]; 4],
    /// The previous frame's camera position in this frame's scene coordinates (w unused).
    pub previous_camera_position: [f32; 4],
    /// Temporal anti-aliasing's sub-pixel offsets of the projection, in NDC: xy this
    /// frame's (already in `proj` and `view_proj`), zw the previous frame's (already in
    /// `previous_view_proj`). Zero without it.
    pub jitter: [f32; 4],
    /// x: the mip bias of material textures ([`crate::taa::TEXTURE_LOD_BIAS`] under
    /// temporal anti-aliasing, else 0); the rest unused.
    pub texture_lod_bias: [f32; 4],
}

impl ViewUniform {
    pub fn new(
        view: Mat4,
        proj: Mat4,
        camera_position: Vec3,
        size: (u32, u32),
        near: f32,
        far: f32,
    ) -> Self {
        let (w, h) = (size.0.max(1) as f32, size.1.max(1) as f32);
        Self {
            view_proj: (proj * view).to_cols_array_2d(),
            view: view.to_cols_array_2d(),
            proj: proj.to_cols_array_2d(),
            inverse_proj: proj.inverse().to_cols_array_2d(),
            inverse_view: view.inverse().to_cols_array_2d(),
            camera_position: camera_position.extend(1.0).to_array(),
            viewport: [w, h, 1.0 / w, 1.0 / h],
            near_far: [near, far, 1.0, 0.0],
            origin: [0.0; 4],
            seeds: [0; 4],
            previous_view_proj: (proj * view).to_cols_array_2d(),
            previous_camera_position: camera_position.extend(1.0).to_array(),
            jitter: [0.0; 4],
            texture_lod_bias: [0.0; 4],
        }
    }
}

impl ViewUniform {
    /// The uniform of an engine's camera, from its own world-to-view and view-to-clip
    /// matrices and its render target's size: the eye, the near and far planes and the
    /// depth convention are read off the matrices ([`ProjectionFacts::of`]), so a
    /// standard, reverse-Z or infinite-far projection needs nothing else. A left-handed
    /// perspective pair (the camera looking down +Z) is turned into the right-handed one
    /// this library works in (looking down -Z) with the same clip space: the same pixels,
    /// the same depth. Refused with the problem named: a matrix with a non-finite entry, a
    /// view that cannot be inverted, a projection that is neither a perspective nor an
    /// orthographic one with depth from 0 to 1.
    pub fn from_matrices(view: Mat4, projection: Mat4, size: (u32, u32)) -> GpuResult<Self> {
        let camera = CameraMatrices::right_handed(view, projection)?;
        let facts = ProjectionFacts::of(camera.projection)?;
        let eye = camera.view.inverse().w_axis.truncate();
        let mut uniform = Self::new(
            camera.view,
            camera.projection,
            eye,
            size,
            facts.near,
            facts.far,
        );
        uniform.near_far[2] = facts.depth.clear_value();
        Ok(uniform)
    }

    /// The world-to-view matrix (right-handed: the camera looks down -Z).
    pub fn view_matrix(&self) -> Mat4 {
        Mat4::from_cols_array_2d(&self.view)
    }

    /// The view-to-clip matrix.
    pub fn projection_matrix(&self) -> Mat4 {
        Mat4::from_cols_array_2d(&self.proj)
    }

    /// The near and far planes' distances (far may be infinite).
    pub fn near_far(&self) -> (f32, f32) {
        (self.near_far[0], self.near_far[1])
    }

    /// The render target's size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.viewport[0] as u32, self.viewport[1] as u32)
    }
}

/// An engine's camera as this library reads it: right-handed view space (looking down -Z).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraMatrices {
    pub view: Mat4,
    pub projection: Mat4,
}

impl CameraMatrices {
    /// The engine's pair, made right-handed where it is a left-handed perspective (its
    /// projection's w is +z): view and projection both flip Z, so `projection * view` is
    /// unchanged. An orthographic projection carries no handedness in its w and is taken
    /// as right-handed.
    pub fn right_handed(view: Mat4, projection: Mat4) -> GpuResult<Self> {
        let refuse = |problem: &str| {
            Err(GpuError::InvalidInput {
                what: "camera".into(),
                problem: problem.into(),
            })
        };
        if !view.is_finite() || !projection.is_finite() {
            return refuse("the view or projection matrix has an entry that is not finite");
        }
        let determinant = view.determinant();
        if !determinant.is_normal() {
            return refuse("the view matrix cannot be inverted (its determinant is 0)");
        }
        if projection.z_axis.w > 0.0 {
            let flip_z = Mat4::from_scale(Vec3::new(1.0, 1.0, -1.0));
            return Ok(Self {
                view: flip_z * view,
                projection: projection * flip_z,
            });
        }
        Ok(Self { view, projection })
    }
}

/// What a right-handed projection matrix with depth from 0 to 1 (wgpu's clip space) says
/// about the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectionFacts {
    /// The distances along the view direction that depth 0 and 1 (or 1 and 0) map to:
    /// `far` is infinite for an infinite-far projection.
    pub near: f32,
    pub far: f32,
    /// Standard (depth 0 at near) or reverse-Z (depth 1 at near).
    pub depth: DepthConvention,
    pub orthographic: bool,
}

impl ProjectionFacts {
    /// Reads the planes and the depth convention off `projection`: depth is an affine
    /// function of 1/distance (perspective) or of the distance (orthographic); where it
    /// is 0 and where it is 1 are the planes, and whether it falls with distance is the
    /// convention. Refused where it is neither kind, where depth does not change with
    /// distance, or where the near plane is not in front of the camera.
    pub fn of(projection: Mat4) -> GpuResult<Self> {
        let refuse = |problem: String| {
            Err(GpuError::InvalidInput {
                what: "camera projection".into(),
                problem,
            })
        };
        // Clip z and w of the view-space point at distance t on the axis: z = -t.
        let (scale, offset) = (-projection.z_axis.z, projection.w_axis.z);
        let orthographic = projection.z_axis.w == 0.0 && projection.w_axis.w == 1.0;
        let perspective = projection.z_axis.w < 0.0 && projection.w_axis.w == 0.0;
        if !(orthographic || perspective) {
            return refuse(format!(
                "neither perspective (w = -z) nor orthographic (w = 1): column z ends in {}, \
                 column w in {}",
                projection.z_axis.w, projection.w_axis.w
            ));
        }
        // Depth d(t) = a + b * u, with u = 1/t (perspective) or u = t (orthographic).
        let (a, b) = if perspective {
            let w_scale = -projection.z_axis.w;
            (scale / w_scale, offset / w_scale)
        } else {
            (offset, scale)
        };
        if b == 0.0 || !b.is_finite() {
            return refuse("depth does not change with distance".into());
        }
        // Where depth is 0 and where it is 1, as distances.
        let distance_at = |depth: f32| {
            let u = (depth - a) / b;
            if perspective { 1.0 / u } else { u }
        };
        let (at_zero, at_one) = (distance_at(0.0), distance_at(1.0));
        // Depth grows with distance for a standard projection: with perspective it falls
        // with u = 1/t, so b < 0; orthographic, it grows with u = t.
        let standard = if perspective { b < 0.0 } else { b > 0.0 };
        let (depth, near, far) = if standard {
            (DepthConvention::Standard, at_zero, at_one)
        } else {
            (DepthConvention::Reverse, at_one, at_zero)
        };
        let far = if far.is_finite() && far > 0.0 {
            far
        } else {
            f32::INFINITY
        };
        let near_ok = if perspective { near > 0.0 } else { near >= 0.0 };
        if !(near_ok && near.is_finite() && far > near) {
            return refuse(format!(
                "the planes it maps depth 0 and 1 to are at {near} and {far}: a projection \
                 with depth from 0 to 1 in front of the camera needs 0 < near < far"
            ));
        }
        Ok(Self {
            near,
            far,
            depth,
            orthographic,
        })
    }
}

/// The uniform buffer and bind group (group 0) holding the frame's [`ViewUniform`].
#[derive(Debug)]
pub struct ViewBinding {
    pub layout: wgpu::BindGroupLayout,
    pub buffer: wgpu::Buffer,
    pub bind_group: wgpu::BindGroup,
}

impl ViewBinding {
    pub fn new(context: &GpuContext) -> Self {
        let device = &context.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("view layout"),
            entries: &[crate::binding::uniform_entry(
                0,
                wgpu::ShaderStages::VERTEX
                    | wgpu::ShaderStages::FRAGMENT
                    | wgpu::ShaderStages::COMPUTE,
            )],
        });
        let buffer = crate::binding::uniform_buffer(
            device,
            "view uniform",
            std::mem::size_of::<ViewUniform>(),
        );
        let bind_group = crate::binding::bind_group(
            context,
            "view bind group",
            &layout,
            crate::binding::buffers_in_order([&buffer]),
        );
        Self {
            layout,
            buffer,
            bind_group,
        }
    }

    pub fn update(&self, context: &GpuContext, uniform: &ViewUniform) {
        context
            .queue
            .write_buffer(&self.buffer, 0, bytemuck::bytes_of(uniform));
    }
}

#[cfg(test)]
mod layout_tests {
    use super::ViewUniform;
    use crate::assert_wgsl_layout;

    #[test]
    fn view_uniform_matches_wgsl() {
        assert_wgsl_layout!(
            crate::base_color::program(),
            "common/view.wgsl",
            View == ViewUniform {
                view_proj: view_proj,
                view: view,
                proj: proj,
                inverse_proj: inverse_proj,
                inverse_view: inverse_view,
                camera_position: camera_position,
                viewport: viewport,
                near_far: near_far,
                origin: origin,
                seeds: seeds,
                previous_view_proj: previous_view_proj,
                previous_camera_position: previous_camera_position,
                jitter: jitter,
                texture_lod_bias: texture_lod_bias,
            }
        );
    }
}

#[cfg(test)]
mod camera_tests {
    use super::{CameraMatrices, ProjectionFacts, ViewUniform};
    use crate::DepthConvention::{Reverse, Standard};
    use glam::camera::{lh, rh};
    use glam::{Mat4, Vec3, Vec4};

    const NEAR: f32 = 0.25;
    const FAR: f32 = 80.0;

    fn facts(projection: Mat4) -> ProjectionFacts {
        ProjectionFacts::of(projection).expect("a valid projection")
    }

    /// Agreement of a plane's distance read back with the one the matrix was made from.
    /// The matrix holds the planes in f32 entries: depth's slope and offset each carry
    /// half an ulp, and the far plane is where `1 - a` (a within ulps of 1, about
    /// near/far from it) cancels, so its relative error grows to about ulp x far/near.
    fn close(read: f32, made: f32) -> bool {
        let tolerance = 4.0 * f32::EPSILON * (FAR / NEAR);
        (read - made).abs() <= tolerance * made.abs()
    }

    #[test]
    fn planes_and_convention_are_read_off_every_projection_kind() {
        use rh::proj::directx;
        let cases = [
            (
                directx::perspective(1.0, 1.5, NEAR, FAR),
                NEAR,
                FAR,
                Standard,
            ),
            (
                directx::perspective(1.0, 1.5, FAR, NEAR),
                NEAR,
                FAR,
                Reverse,
            ),
            (
                directx::perspective_infinite(1.0, 1.5, NEAR),
                NEAR,
                f32::INFINITY,
                Standard,
            ),
            (
                directx::perspective_infinite_reverse(1.0, 1.5, NEAR),
                NEAR,
                f32::INFINITY,
                Reverse,
            ),
            (
                directx::orthographic(-2.0, 2.0, -1.0, 1.0, NEAR, FAR),
                NEAR,
                FAR,
                Standard,
            ),
            (
                directx::orthographic(-2.0, 2.0, -1.0, 1.0, FAR, NEAR),
                NEAR,
                FAR,
                Reverse,
            ),
        ];
        for (index, (projection, near, far, depth)) in cases.into_iter().enumerate() {
            let read = facts(projection);
            assert_eq!(read.depth, depth, "case {index}");
            assert!(close(read.near, near), "case {index}: near {}", read.near);
            assert!(
                read.far == far || close(read.far, far),
                "case {index}: far {}",
                read.far
            );
        }
    }

    #[test]
    fn a_left_handed_camera_sees_the_same_clip_space_right_handed() {
        let eye = Vec3::new(1.0, 2.0, 3.0);
        let target = Vec3::new(0.0, 1.0, -4.0);
        let view = lh::view::look_at_mat4(eye, target, Vec3::Y);
        let projection = lh::proj::directx::perspective(1.0, 1.5, NEAR, FAR);
        let camera = CameraMatrices::right_handed(view, projection).unwrap();
        let point = Vec4::new(0.3, 1.2, -2.0, 1.0);
        let (before, after) = (
            projection * view * point,
            camera.projection * camera.view * point,
        );
        assert!(
            (before - after).abs().max_element() < 1e-5,
            "{before} {after}"
        );
        // In front of the camera is -Z in the turned view space.
        assert!((camera.view * target.extend(1.0)).z < 0.0);
        let uniform = ViewUniform::from_matrices(view, projection, (64, 32)).unwrap();
        assert!((Vec4::from(uniform.camera_position).truncate() - eye).length() < 1e-5);
        assert!(close(uniform.near_far[0], NEAR) && close(uniform.near_far[1], FAR));
        assert_eq!(uniform.near_far[2], 1.0);
    }

    #[test]
    fn reverse_z_sets_the_empty_depth_to_zero() {
        let projection = rh::proj::directx::perspective_infinite_reverse(1.0, 1.5, NEAR);
        let uniform = ViewUniform::from_matrices(Mat4::IDENTITY, projection, (8, 8)).unwrap();
        assert_eq!(uniform.near_far[2], 0.0);
        assert_eq!(uniform.near_far[1], f32::INFINITY);
    }

    #[test]
    fn unusable_matrices_are_refused_with_the_problem_named() {
        let good = rh::proj::directx::perspective(1.0, 1.5, NEAR, FAR);
        let mut nan = good;
        nan.x_axis.x = f32::NAN;
        let flat = Mat4::from_scale(Vec3::new(1.0, 1.0, 0.0));
        let mut constant_depth = good;
        // Clip z proportional to w: depth 0.5 at every distance.
        constant_depth.z_axis.z = -0.5;
        constant_depth.w_axis.z = 0.0;
        // OpenGL's depth from -1 to 1 puts depth 0 between the planes.
        let opengl = rh::proj::opengl::perspective(1.0, 1.5, NEAR, FAR);
        let mut neither = good;
        neither.w_axis.w = 0.5;
        let mut behind = good;
        behind.w_axis.z = -behind.w_axis.z;
        for (view, projection, expected) in [
            (Mat4::IDENTITY, nan, "not finite"),
            (flat, good, "cannot be inverted"),
            (Mat4::IDENTITY, neither, "neither perspective"),
            (Mat4::IDENTITY, constant_depth, "does not change"),
            (Mat4::IDENTITY, behind, "0 < near < far"),
        ] {
            let error = ViewUniform::from_matrices(view, projection, (8, 8))
                .expect_err(expected)
                .to_string();
            assert!(error.contains(expected), "{error}");
        }
        // OpenGL's -1..1 depth maps 0 to a plane between its near and far: refused or
        // read as planes other than the engine's, never silently its own.
        if let Ok(read) = ProjectionFacts::of(opengl) {
            assert!(!close(read.near, NEAR), "{read:?}");
        }
    }
}
