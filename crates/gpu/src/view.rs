//! The per-frame camera uniform (`shaders/common/view.wgsl`), bound at group 0.

use glam::{Mat4, Vec3};

use crate::context::GpuContext;

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
